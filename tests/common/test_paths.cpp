#include "test_paths.h"

#if defined(__SANITIZE_THREAD__)
#include <tbb/global_control.h>
// As in app/main.cpp: TSan cannot see TBB's synchronisation, so TBB loops run serially.
static const tbb::global_control tsan_serial_tbb(tbb::global_control::max_allowed_parallelism, 1);
#endif

#include <unistd.h>

#include <algorithm>

namespace lumar::test {

std::filesystem::path source_dir() { return LUMAR_SOURCE_DIR; }
std::filesystem::path shared_dir() { return LUMAR_SHARED_DIR; }
std::filesystem::path lumar_binary() { return LUMAR_BINARY; }

int time_scale() { return LUMAR_TEST_TIME_SCALE; }

std::vector<std::filesystem::path> checkerboard_images() {
  std::vector<std::filesystem::path> images;
  for (const auto& entry : std::filesystem::directory_iterator(shared_dir() / "data/calib/checkerboard-9x6"))
    if (entry.path().extension() == ".jpg") images.push_back(entry.path());
  std::sort(images.begin(), images.end());
  return images;
}

std::filesystem::path scratch_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / ("lumar-test-" + std::to_string(getpid()) + "-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace lumar::test
