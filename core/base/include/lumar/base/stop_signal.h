#pragma once
// SIGINT / SIGTERM as a flag that long-running commands poll, so they can stop
// cleanly (close files, stop threads) instead of dying mid-write.
#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <type_traits>

namespace lumar {

// Installs the handlers (once); from then on the signals only set the flag.
void catch_stop_signals();
bool stop_requested();
// Throws Interrupted("<what>; nothing written") when a stop was requested: for loops in
// libraries that run long (board detection, calibration), so a command stops within one
// step of its work.
void throw_if_stopped(const std::string& what);

// Runs `work` on a thread of its own and waits for it, looking at the stop flag every
// 50 ms, for a library call that runs long and cannot look itself (OpenCV's
// calibrateCamera takes a minute over 150 views). On a stop it throws as throw_if_stopped
// does at once and leaves the thread to finish alone, so `work` must own all it touches
// (capture by value); the process is about to end (app/main.cpp ends it without running
// static destructors under that thread).
template <class Work>
std::invoke_result_t<Work&> run_until_stopped(Work work, const std::string& what) {
  using Result = std::invoke_result_t<Work&>;
  auto task = std::make_shared<std::packaged_task<Result()>>(std::move(work));
  std::future<Result> done = task->get_future();
  std::thread([task] { (*task)(); }).detach();
  while (done.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) throw_if_stopped(what);
  return done.get();
}

}  // namespace lumar
