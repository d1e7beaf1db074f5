#include "lumar/tracking/record_parser.h"

#include <string>
#include <utility>

#include "lumar/base/error.h"
#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {

RecordParser::RecordParser(TrackerFormat format, int baud)
    : format_(std::move(format)), baud_(baud), length_(tracking::record_length(format_)) {
  if (baud <= 0)
    throw InputError("tracker record parser: baud " + std::to_string(baud) +
                     " is not positive; use the line's baud rate");
}

void RecordParser::push(const ByteChunk& chunk) {
  const std::size_t n = chunk.bytes.size();
  bytes_.insert(bytes_.end(), chunk.bytes.begin(), chunk.bytes.end());
  arrival_.reserve(arrival_.size() + n);
  for (std::size_t i = 0; i < n; ++i)
    arrival_.push_back(chunk.arrival - transmission_time(std::int64_t(n - 1 - i), baud_));
  scan();
}

void RecordParser::scan() {
  const std::size_t n = bytes_.size();
  const std::size_t length = std::size_t(length_);
  std::size_t head = 0;
  while (head < n) {
    if (head + 1 >= n) {
      // The next byte decides whether this one starts a record; only a start byte waits.
      if (is_record_start(bytes_[head], '1', format_)) break;
      ++skipped_, ++head;
      continue;
    }
    if (!is_record_start(bytes_[head], bytes_[head + 1], format_)) {
      ++skipped_, ++head;
      continue;
    }
    if (n - head < length) break;  // wait for the rest of the candidate
    auto record = decode_record(std::span(bytes_).subspan(head, length), format_);
    if (!record) {
      // Give up on this start only; the next byte may begin a good record.
      ++rejected_, ++skipped_, ++head;
      continue;
    }
    ready_.push_back({std::move(*record), arrival_[head]});
    ++accepted_;
    head += length;
  }
  // What is left is shorter than one record, so this stays cheap.
  bytes_.erase(bytes_.begin(), bytes_.begin() + std::ptrdiff_t(head));
  arrival_.erase(arrival_.begin(), arrival_.begin() + std::ptrdiff_t(head));
}

std::optional<TimedIsotrakRecord> RecordParser::next() {
  if (ready_.empty()) return std::nullopt;
  TimedIsotrakRecord r = std::move(ready_.front());
  ready_.pop_front();
  return r;
}

std::vector<TimedIsotrakRecord> RecordParser::take_all() {
  std::vector<TimedIsotrakRecord> out(std::make_move_iterator(ready_.begin()), std::make_move_iterator(ready_.end()));
  ready_.clear();
  return out;
}

}  // namespace lumar::tracking
