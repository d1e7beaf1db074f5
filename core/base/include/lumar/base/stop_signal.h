#pragma once
// SIGINT / SIGTERM as a flag that long-running commands poll, so they can stop
// cleanly (close files, stop threads) instead of dying mid-write.
#include <string>

namespace lumar {

// Installs the handlers (once); from then on the signals only set the flag.
void catch_stop_signals();
bool stop_requested();
// Throws Interrupted("<what>; nothing written") when a stop was requested: for loops in
// libraries that run long (board detection, calibration), so a command stops within one
// step of its work.
void throw_if_stopped(const std::string& what);

}  // namespace lumar
