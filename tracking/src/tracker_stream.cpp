#include "lumar/tracking/tracker_stream.h"

#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/record_parser.h"
#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {

DecodedTrackerStream decode_tracker_stream(std::span<const ByteChunk> chunks, const TrackerFormat& format, int baud,
                                           Nanos device_latency) {
  RecordParser parser(format, baud);
  DecodedTrackerStream out;
  for (const ByteChunk& chunk : chunks) {
    parser.push(chunk);
    for (const auto& r : parser.take_all()) {
      const Nanos time = measurement_time(r.first_byte_arrival, baud, device_latency);
      if (auto sample = to_pose_sample(r.record, format.output, time)) out.samples.push_back(*sample);
    }
  }
  out.records = parser.accepted_records();
  out.rejected_records = parser.rejected_records();
  out.skipped_bytes = parser.skipped_bytes();
  return out;
}

}  // namespace lumar::tracking
