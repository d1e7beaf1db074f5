// Fuzz target: the tracker record parser in all four formats (ISOTRAK II / Fastrak,
// ASCII / binary), fed in arbitrary chunks.
//
// Input layout: byte 0 picks the format, byte 1 the chunking, the rest is the line.
//   byte 0  bit 0 binary, bit 1 Fastrak, bit 2 centimetres,
//           bits 3-4 output list: 2,4,1 | 2,11,1 | 2,4,11,1 | 2,11
//   byte 1  0: everything in one push; n > 0: chunks of 1..n bytes (a fixed sequence)
// Checks (a failure aborts, which the fuzzer reports as a crash):
//   - bytes pushed == accepted * record length + skipped + pending, after every push;
//   - every accepted record re-encodes to bytes that decode to the same record;
//   - every pose made from a record is finite with a unit quaternion.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/record_codec.h"
#include "lumar/tracking/record_parser.h"

namespace {

using namespace lumar::tracking;

void check(bool ok) {
  if (!ok) std::abort();
}

TrackerFormat pick_format(std::uint8_t b) {
  static const std::vector<int> kLists[4] = {{2, 4, 1}, {2, 11, 1}, {2, 4, 11, 1}, {2, 11}};
  OutputFormat output;
  output.output_list = kLists[(b >> 3) & 3];
  output.centimetres = b & 4;
  return TrackerFormat::of(b & 2 ? Device::Fastrak : Device::Isotrak2, b & 1, output);
}

bool same(const IsotrakRecord& a, const IsotrakRecord& b) {
  return a.station == b.station && a.status == b.status && a.position == b.position &&
         a.attitude_deg == b.attitude_deg && a.quaternion == b.quaternion;
}

void check_record(const IsotrakRecord& r, const TrackerFormat& format) {
  try {
    const auto again = decode_record(encode_record(r, format), format);
    check(again.has_value() && same(*again, r));
  } catch (const std::invalid_argument&) {
    // Only the int16 value -32768 decodes but is not sent (full scale is +-32767).
    check(format.binary && format.device == Device::Isotrak2);
  }
  if (const auto sample = to_pose_sample(r, format.output, 0)) {
    const lumar::Pose& p = sample->T_transmitter_sensor;
    check(p.is_finite());
    check(std::abs(glm::length(p.rotation) - 1.0) < 1e-9);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const TrackerFormat format = pick_format(data[0]);
  const std::size_t max_chunk = data[1];
  data += 2, size -= 2;

  RecordParser parser(format, 115200);
  std::size_t pushed = 0;
  std::uint32_t lcg = 12345;
  for (std::size_t at = 0; at < size;) {
    std::size_t n = size - at;
    if (max_chunk > 0) {
      lcg = lcg * 1664525u + 1013904223u;
      n = std::min(n, 1 + (lcg >> 16) % max_chunk);
    }
    ByteChunk chunk;
    chunk.arrival = lumar::Nanos(at + n) * 1000;
    chunk.bytes.assign(data + at, data + at + n);
    parser.push(chunk);
    at += n, pushed += n;
    check(parser.accepted_records() * std::size_t(parser.record_length()) + parser.skipped_bytes() +
              parser.pending_bytes() ==
          pushed);
    check(parser.pending_bytes() < std::size_t(parser.record_length()));
    for (const auto& r : parser.take_all()) check_record(r.record, format);
  }
  return 0;
}
