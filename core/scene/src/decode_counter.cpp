#include "decode_counter.h"

#include <mutex>

namespace lumar {

namespace {
std::mutex& counts_mutex() {
  static std::mutex m;
  return m;
}
std::map<std::filesystem::path, int>& counts() {
  static std::map<std::filesystem::path, int> c;
  return c;
}
}  // namespace

void count_decode(const std::filesystem::path& file) {
  std::error_code ec;
  const auto key = std::filesystem::weakly_canonical(file, ec);
  std::lock_guard lock(counts_mutex());
  ++counts()[ec ? file : key];
}

std::map<std::filesystem::path, int> decode_counts() {
  std::lock_guard lock(counts_mutex());
  return counts();
}

}  // namespace lumar
