#pragma once
// A tracker's recorded bytes decoded as a replay sees them, the one place this is done:
// the chunks through the real protocol parser (record_parser.h), every record stamped
// with its measurement time (its first byte's arrival, less transmission time and the
// device latency: timestamping.h) and converted to a pose (pose_conversion.h).
#include <cstddef>
#include <span>
#include <vector>

#include "lumar/base/time.h"
#include "lumar/tracking/byte_chunk.h"
#include "lumar/tracking/pose_sample.h"
#include "lumar/tracking/record_codec.h"

namespace lumar::tracking {

struct DecodedTrackerStream {
  std::vector<PoseSample> samples;  // every station's, in the order the records arrived
  std::size_t records = 0, rejected_records = 0, skipped_bytes = 0;  // the parser's counts
};

// Throws InputError for an unusable format or a baud <= 0.
DecodedTrackerStream decode_tracker_stream(std::span<const ByteChunk> chunks, const TrackerFormat& format, int baud,
                                           Nanos device_latency);

}  // namespace lumar::tracking
