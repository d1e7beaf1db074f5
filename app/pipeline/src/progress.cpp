#include "lumar/pipeline/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace lumar::pipeline {

Progress::Progress(std::string what, int total, std::string unit, bool quiet_off_terminal)
    : what_(std::move(what)),
      unit_(std::move(unit)),
      total_(std::max(1, total)),
      tty_(isatty(2)),
      quiet_(quiet_off_terminal) {}

void Progress::update(int done) {
  last_done_ = done;
  const int tenth = done * 10 / total_;
  if (tty_) {
    const auto now = std::chrono::steady_clock::now();
    // A few redraws a second are enough to read; more only cost time.
    if (done != total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    const double seconds = std::chrono::duration<double>(now - start_).count();
    const double rate = seconds > 0 ? done / seconds : 0.0;
    const int filled = std::clamp(done * 30 / total_, 0, 30);
    std::fprintf(stderr, "\r%s [%s%s] %d/%d %s", what_.c_str(), std::string(filled, '#').c_str(),
                 std::string(30 - filled, ' ').c_str(), done, total_, unit_.c_str());
    if (rate > 0) std::fprintf(stderr, ", %.1f %s/s, %.0f s left ", rate, unit_.c_str(), (total_ - done) / rate);
    open_line_ = true;
    if (done == total_) finish();
  } else if (!quiet_ && tenth != last_tenth_) {
    std::fprintf(stderr, "%s: %d/%d\n", what_.c_str(), done, total_);
  }
  last_tenth_ = tenth;
}

void Progress::finish() {
  if (tty_ && open_line_) std::fprintf(stderr, "\n");
  open_line_ = false;
}

}  // namespace lumar::pipeline
