#pragma once
// tracker.raw: the tracker's bytes as they arrived, as self-checking chunks
// (layout in lumar/capture/recording_format.h).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "lumar/tracking/byte_chunk.h"

namespace lumar::capture {

// Appends one chunk (header + payload) to `out`.
void append_tracker_chunk(std::string& out, const tracking::ByteChunk& chunk);

// The chunks of `data` up to the first torn or bad one (short header, short
// payload, wrong magic or CRC); `ignored_bytes` gets the count of bytes after them.
std::vector<tracking::ByteChunk> parse_tracker_chunks(std::string_view data, std::size_t* ignored_bytes);

}  // namespace lumar::capture
