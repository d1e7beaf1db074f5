#pragma once
// Paths the tests need: the checkout, ../shared beside it, the lumar binary, scratch space.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace lumar::test {

std::filesystem::path source_dir();
std::filesystem::path shared_dir();
std::filesystem::path lumar_binary();
// The 13 shared photographs of the 9x6 checkerboard, sorted by name.
std::vector<std::filesystem::path> checkerboard_images();
// How many times slower this build runs than a release build (8 under ThreadSanitizer, 3
// under ASan + UBSan, else 1; tests/CMakeLists.txt), for the few limits a test times itself.
int time_scale();
// A fresh, empty directory for this test, which the caller removes (Scratch does).
std::filesystem::path scratch_dir(const std::string& name);

// A scratch folder for one test, removed when the test ends; kept when it failed, so that
// what it wrote can be looked at (its path is printed).
struct Scratch {
  explicit Scratch(const std::string& name) : dir(scratch_dir(name)) {}
  ~Scratch() {
    if (::testing::Test::HasFailure()) {
      std::fprintf(stderr, "the failed test's files are kept in %s\n", dir.c_str());
      return;
    }
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  std::filesystem::path dir;
};

}  // namespace lumar::test
