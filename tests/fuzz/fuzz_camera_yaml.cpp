// The camera calibration reader (load_camera_file, OpenCV's FileStorage behind it): any
// bytes give a valid camera or one InputError.
#include <cmath>

#include "fuzz_input.h"
#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lumar;
  const auto path = fuzz::input_file(data, size, "camera.yml");
  try {
    const calib::CameraFile camera = calib::load_camera_file(path);
    FUZZ_CHECK(camera.intrinsics.is_valid());
    for (double d : camera.intrinsics.distortion) FUZZ_CHECK(std::isfinite(d));
    FUZZ_CHECK(std::isfinite(camera.avg_reprojection_error) && camera.avg_reprojection_error >= 0);
  } catch (const InputError&) {
  }
  return 0;
}
