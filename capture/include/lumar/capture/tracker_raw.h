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

// The whole chunks of `data`. A damaged one (wrong magic, a length past the end, a CRC
// mismatch) is skipped up to the next magic; a torn last one (a write cut short) is
// dropped. `ignored_bytes` gets the count of bytes in no whole chunk; `torn_tail_bytes`
// those of them that are a last chunk cut short (what a crash leaves, not damage).
std::vector<tracking::ByteChunk> parse_tracker_chunks(std::string_view data, std::size_t* ignored_bytes,
                                                      std::size_t* torn_tail_bytes = nullptr);

}  // namespace lumar::capture
