#include "lumar/base/stop_signal.h"

#include "lumar/base/error.h"

#include <csignal>

namespace lumar {

namespace {
volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int) { g_stop = 1; }
}  // namespace

void catch_stop_signals() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool stop_requested() { return g_stop != 0; }

void throw_if_stopped(const std::string& what) {
  if (stop_requested()) throw Interrupted(what + "; nothing written");
}

}  // namespace lumar
