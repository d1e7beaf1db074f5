#pragma once
// Helpers shared by the fuzz targets. The project's loaders take paths, so an input is
// written to a file in a scratch folder of this process, and a target's property
// checks abort (which libFuzzer reports as a crash) with a message saying which failed.
#include <unistd.h>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace lumar::fuzz {

// A folder of this process's own, under /dev/shm when there is one (no disk writes).
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    std::error_code ec;
    const std::filesystem::path base =
        std::filesystem::is_directory("/dev/shm", ec) ? "/dev/shm" : std::filesystem::temp_directory_path();
    auto d = base / ("lumar-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline void write_file(const std::filesystem::path& path, const void* data, std::size_t size) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), std::streamsize(size));
}

// The input as the file `name` in the scratch folder.
inline std::filesystem::path input_file(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const auto path = scratch() / name;
  write_file(path, data, size);
  return path;
}

[[noreturn]] inline void property_failed(const char* what) {
  std::fprintf(stderr, "fuzz property failed: %s\n", what);
  std::abort();
}

}  // namespace lumar::fuzz

#define FUZZ_CHECK(condition)                                     \
  do {                                                            \
    if (!(condition)) ::lumar::fuzz::property_failed(#condition); \
  } while (0)
