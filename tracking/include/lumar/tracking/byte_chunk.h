#pragma once
// Bytes as they came off the tracker's line, stamped when the read returned
// (CLOCK_MONOTONIC; in recordings, since the recording's start). Recordings keep
// these raw so that every replay runs the real protocol parser.
#include <cstdint>
#include <vector>

#include "lumar/base/time.h"

namespace lumar::tracking {

struct ByteChunk {
  Nanos arrival = 0;  // when the last byte of the chunk had arrived
  std::vector<std::uint8_t> bytes;
};

}  // namespace lumar::tracking
