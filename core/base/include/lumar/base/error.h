#pragma once
// Errors that reach the user. One line each: which file or device, what is wrong,
// what to do. InputError exits with status 2, RuntimeError with status 1, Interrupted
// with 130.
#include <stdexcept>
#include <string>

namespace lumar {

// The user gave something unusable: a missing or corrupt file, a bad option.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Something failed while running: a device vanished, a disk filled, OpenGL failed.
struct RuntimeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Stopped by SIGINT or SIGTERM (lumar/base/stop_signal.h) before the work was done: exits
// with status 130, after removing what was not finished.
struct Interrupted : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace lumar
