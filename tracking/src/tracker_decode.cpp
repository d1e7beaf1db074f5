#include "lumar/tracking/tracker_decode.h"

#include <cstdio>

#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/record_parser.h"

namespace lumar::tracking {

DecodeCounts decode_to_csv(std::span<const ByteChunk> chunks, const TrackerFormat& format, std::ostream& out) {
  RecordParser parser(format);  // the baud only matters for times, which are not written
  DecodeCounts counts;
  out << kDecodeCsvHeader << '\n';
  char line[256];
  auto write = [&] {
    for (const auto& r : parser.take_all()) {
      const auto sample = to_pose_sample(r.record, format.output, 0);
      if (!sample) {
        ++counts.without_pose;
        continue;
      }
      const glm::dvec3& p = sample->T_transmitter_sensor.translation;
      const glm::dquat& q = sample->T_transmitter_sensor.rotation;
      std::snprintf(line, sizeof line, "%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", sample->station, p.x, p.y, p.z, q.w,
                    q.x, q.y, q.z);
      out << line;
      ++counts.lines;
    }
  };
  for (const ByteChunk& chunk : chunks) {
    parser.push(chunk);
    write();
  }
  counts.records = parser.accepted_records();
  counts.rejected_records = parser.rejected_records();
  counts.torn_tail_bytes = parser.pending_bytes();
  counts.skipped_bytes = parser.skipped_bytes() + counts.torn_tail_bytes;
  return counts;
}

std::string decode_summary(const DecodeCounts& c) {
  std::string s = std::to_string(c.records) + " records, " + std::to_string(c.rejected_records) +
                  " rejected records, " + std::to_string(c.skipped_bytes) + " skipped bytes";
  if (c.torn_tail_bytes > 0) s += " (" + std::to_string(c.torn_tail_bytes) + " in a torn record at the end)";
  if (c.without_pose > 0) s += ", " + std::to_string(c.without_pose) + " records without a usable pose";
  return s;
}

}  // namespace lumar::tracking
