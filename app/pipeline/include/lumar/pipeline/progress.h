#pragma once
// How far a long job has come, on stderr: on a terminal a bar redrawn in place with the
// count, the rate and the time left; elsewhere (a log, a pipe) a line per tenth, or
// nothing when `quiet_off_terminal`.
#include <chrono>
#include <string>

namespace lumar::pipeline {

class Progress {
 public:
  Progress(std::string what, int total, std::string unit = "frames", bool quiet_off_terminal = false);
  void update(int done);
  void finish();  // ends the bar's line on a terminal (if update() did not reach the total)

 private:
  std::string what_, unit_;
  int total_;
  bool tty_, quiet_;
  int last_tenth_ = -1, last_done_ = 0;
  bool open_line_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_draw_{};
};

}  // namespace lumar::pipeline
