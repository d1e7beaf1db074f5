#pragma once
// Streaming parser for every record format (record_codec.h). Push chunks as they come
// off the line; pull records.
//
// Time: a chunk's `arrival` is when its LAST byte arrived; byte i of an n-byte chunk
// arrived at arrival - (n-1-i) * byte_time, with byte_time = 10 bits / baud (8N1),
// rounded to the nanosecond (see timestamping.h). Each record carries the arrival
// time of its first byte.
//
// Resynchronisation: the parser hunts byte by byte for a candidate start
// (is_record_start: '0', or 0xB0 for ISOTRAK II binary, followed by a station digit
// in 1..max_station). A candidate whose full record does not decode is rejected and
// the hunt resumes at the very next byte, so a good record that follows a torn one is
// never lost (VRPN instead flushes its input buffer and loses it).
// Counters: skipped_bytes() counts every consumed byte that is not part of an
// accepted record (garbage, and the bytes of rejected candidates);
// rejected_records() counts candidate starts whose record failed to decode. A start
// byte followed by an out-of-range station is not a candidate: its bytes are skipped
// but it is not counted as a rejected record. At every moment
//   accepted_records() * record_length() + skipped_bytes() + pending_bytes()
// equals the number of bytes pushed.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "lumar/tracking/byte_chunk.h"
#include "lumar/tracking/isotrak_record.h"
#include "lumar/tracking/record_codec.h"

namespace lumar::tracking {

class RecordParser {
 public:
  // Throws InputError for an unusable format or a baud <= 0.
  explicit RecordParser(TrackerFormat format, int baud = 115200);

  void push(const ByteChunk& chunk);

  // Oldest parsed record not yet taken, or nullopt.
  std::optional<TimedIsotrakRecord> next();
  // All parsed records not yet taken, oldest first.
  std::vector<TimedIsotrakRecord> take_all();

  std::size_t available() const { return ready_.size(); }
  std::size_t accepted_records() const { return accepted_; }
  std::size_t rejected_records() const { return rejected_; }
  std::size_t skipped_bytes() const { return skipped_; }
  // Bytes held back because they may start a record that is not complete yet.
  std::size_t pending_bytes() const { return bytes_.size(); }

  const TrackerFormat& tracker_format() const { return format_; }
  const OutputFormat& format() const { return format_.output; }
  int record_length() const { return length_; }
  int baud() const { return baud_; }

 private:
  void scan();

  TrackerFormat format_;
  int baud_;
  int length_;
  std::vector<std::uint8_t> bytes_;  // received, not yet consumed
  std::vector<Nanos> arrival_;       // arrival time of each byte in bytes_
  std::deque<TimedIsotrakRecord> ready_;
  std::size_t accepted_ = 0, rejected_ = 0, skipped_ = 0;
};

}  // namespace lumar::tracking
