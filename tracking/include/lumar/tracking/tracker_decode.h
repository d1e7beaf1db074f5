#pragma once
// `lumar tracker decode`: raw tracker bytes (as chunks) -> CSV of poses, one line per
// valid record: station,x,y,z,qw,qx,qy,qz in metres and a unit quaternion (w first),
// transmitter frame. The same parser and conversion as the live path.
#include <cstddef>
#include <ostream>
#include <span>
#include <string>

#include "lumar/tracking/byte_chunk.h"
#include "lumar/tracking/record_codec.h"

namespace lumar::tracking {

inline constexpr const char* kDecodeCsvHeader = "station,x,y,z,qw,qx,qy,qz";

struct DecodeCounts {
  std::size_t records = 0;           // records decoded (accepted by the parser)
  std::size_t rejected_records = 0;  // candidate records that failed to decode
  std::size_t skipped_bytes = 0;     // bytes outside accepted records, a torn tail included
  std::size_t torn_tail_bytes = 0;   // of which: an incomplete record at the very end
  std::size_t without_pose = 0;      // decoded, but no usable pose (e.g. a bad quaternion): no line
  std::size_t lines = 0;             // CSV lines written (records - without_pose)
};

// Writes the header and one line per record with a usable pose (positions with 6
// decimals, i.e. micrometres; quaternion components with 6 decimals).
// Throws InputError for an unusable format.
DecodeCounts decode_to_csv(std::span<const ByteChunk> chunks, const TrackerFormat& format, std::ostream& out);

// One line for stderr: "<n> records, <r> rejected records, <s> skipped bytes" plus the
// torn tail and records without a pose when there are any.
std::string decode_summary(const DecodeCounts& counts);

}  // namespace lumar::tracking
