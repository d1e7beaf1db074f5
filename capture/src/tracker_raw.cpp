#include "lumar/capture/tracker_raw.h"

#include <zlib.h>

#include <cstdint>
#include <limits>

#include "lumar/base/error.h"
#include "lumar/capture/recording_format.h"

namespace lumar::capture {
namespace {

// Explicit little-endian bytes: the file must read the same on any host.
void put_le(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(char((value >> (8 * i)) & 0xFF));
}

std::uint64_t get_le(const unsigned char* p, int bytes) {
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value |= std::uint64_t(p[i]) << (8 * i);
  return value;
}

std::uint32_t crc_of(const std::uint8_t* data, std::size_t size) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths; feed large payloads in pieces.
  while (size > 0) {
    const uInt piece = uInt(std::min<std::size_t>(size, 1u << 30));
    crc = crc32(crc, data, piece);
    data += piece;
    size -= piece;
  }
  return std::uint32_t(crc);
}

}  // namespace

void append_tracker_chunk(std::string& out, const tracking::ByteChunk& chunk) {
  if (chunk.bytes.size() > std::numeric_limits<std::uint32_t>::max())
    throw InputError("tracker chunk of " + std::to_string(chunk.bytes.size()) +
                     " bytes is too large for tracker.raw; split it");
  put_le(out, kTrackerChunkMagic, 4);
  put_le(out, std::uint64_t(chunk.arrival), 8);
  put_le(out, chunk.bytes.size(), 4);
  put_le(out, crc_of(chunk.bytes.data(), chunk.bytes.size()), 4);
  out.append(reinterpret_cast<const char*>(chunk.bytes.data()), chunk.bytes.size());
}

std::vector<tracking::ByteChunk> parse_tracker_chunks(std::string_view data, std::size_t* ignored_bytes,
                                                      std::size_t* torn_tail_bytes) {
  std::vector<tracking::ByteChunk> chunks;
  const auto* p = reinterpret_cast<const unsigned char*>(data.data());
  const std::string_view magic("LTRK", 4);
  std::size_t pos = 0, good = 0, end_of_good = 0;
  while (data.size() - pos >= kTrackerChunkHeaderBytes) {
    const unsigned char* h = p + pos;
    const auto arrival = Nanos(get_le(h + 4, 8));
    const std::size_t length = get_le(h + 12, 4);
    const auto crc = std::uint32_t(get_le(h + 16, 4));
    const unsigned char* payload = h + kTrackerChunkHeaderBytes;
    if (get_le(h, 4) == kTrackerChunkMagic && data.size() - pos - kTrackerChunkHeaderBytes >= length &&
        crc_of(payload, length) == crc) {
      chunks.push_back({arrival, std::vector<std::uint8_t>(payload, payload + length)});
      pos += kTrackerChunkHeaderBytes + length;
      good += kTrackerChunkHeaderBytes + length;
      end_of_good = pos;
      continue;
    }
    // A damaged chunk: go on from the next magic, so that one bad length or flipped bit
    // loses one chunk and not the rest of the recording. The CRC rejects a false magic.
    const std::size_t next = data.find(magic, pos + 1);
    if (next == std::string_view::npos) break;
    pos = next;
  }
  if (ignored_bytes) *ignored_bytes = data.size() - good;
  if (torn_tail_bytes) {
    // A write cut short: the last chunk after the whole ones runs past the end of the
    // data (or its magic itself is cut). A damaged chunk before it is counted as damage.
    std::size_t last = data.rfind(magic);
    if (last == std::string_view::npos || last < end_of_good) last = end_of_good;
    const std::string_view tail = data.substr(last);
    bool torn = false;
    if (tail.size() < 4) {
      torn = tail == magic.substr(0, tail.size());
    } else if (tail.substr(0, 4) == magic) {
      torn =
          tail.size() < kTrackerChunkHeaderBytes || tail.size() - kTrackerChunkHeaderBytes < get_le(p + last + 12, 4);
    }
    *torn_tail_bytes = torn ? tail.size() : 0;
  }
  return chunks;
}

}  // namespace lumar::capture
