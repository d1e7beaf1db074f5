// lumar: the command line. Each subcommand lives in its own file (cmd_*.cpp) and
// registers itself through register_*(); errors become one line and an exit status.
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>

#include "commands.h"
#include "lumar/base/error.h"

#if defined(__SANITIZE_THREAD__)
#include <tbb/global_control.h>
// ThreadSanitizer cannot see TBB's own synchronisation (libtbb is not instrumented), so
// every parallel loop would be reported as a race: the TSan build runs TBB loops on the
// calling thread and checks Lumar's own threads (capture, tracker, live pipelines).
static const tbb::global_control tsan_serial_tbb(tbb::global_control::max_allowed_parallelism, 1);
#endif

namespace {

// What a command did goes to stdout; warnings and debug detail go to stderr, where
// scripts and people look for trouble. Each line is flushed, so the two stay in order
// on a terminal.
class SplitSink : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    spdlog::memory_buf_t text;
    formatter_->format(msg, text);
    std::FILE* out = msg.level == spdlog::level::info ? stdout : stderr;
    std::fwrite(text.data(), 1, text.size(), out);
    std::fflush(out);
  }
  void flush_() override {
    std::fflush(stdout);
    std::fflush(stderr);
  }
};

}  // namespace

int main(int argc, char** argv) {
  // FFmpeg's own log lines (e.g. "overread 8" on a damaged segment) would break the
  // promise of one clear error line; Lumar detects and reports those faults itself.
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
  CLI::App app{"lumar: composite virtual diffuse objects, lit by the real room, into camera video"};
  app.set_version_flag("--version", LUMAR_VERSION);
  app.require_subcommand(1);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Log more detail to stderr");
  lumar::app::register_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("lumar", std::make_shared<SplitSink>()));
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  spdlog::set_pattern("%v");
  try {
    lumar::app::run_selected(app);
    return 0;
  } catch (const lumar::InputError& e) {
    std::fprintf(stderr, "lumar: error: %s\n", e.what());
    return 2;
  } catch (const lumar::Interrupted& e) {
    std::fprintf(stderr, "lumar: stopped: %s\n", e.what());
    // At once: a library call left running on its own thread (run_until_stopped) must
    // not meet static destructors. Every file was closed or removed while unwinding.
    std::fflush(nullptr);
    std::_Exit(130);
  } catch (const lumar::RuntimeError& e) {
    std::fprintf(stderr, "lumar: failed: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lumar: failed: %s\n", e.what());
    return 1;
  }
}
