#include "test_paths.h"

#include <unistd.h>

namespace lumar::test {

std::filesystem::path source_dir() { return LUMAR_SOURCE_DIR; }
std::filesystem::path shared_dir() { return LUMAR_SHARED_DIR; }
std::filesystem::path lumar_binary() { return LUMAR_BINARY; }

std::filesystem::path scratch_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() /
             ("lumar-test-" + std::to_string(getpid()) + "-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace lumar::test
