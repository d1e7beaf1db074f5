#pragma once
// SIGINT / SIGTERM as a flag that long-running commands poll, so they can stop
// cleanly (close files, stop threads) instead of dying mid-write.
namespace lumar {

// Installs the handlers (once); from then on the signals only set the flag.
void catch_stop_signals();
bool stop_requested();

}  // namespace lumar
