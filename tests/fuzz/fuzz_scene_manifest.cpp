// The scene manifest reader (load_scene): any bytes give a Scene or one InputError, never
// another exception or a crash, and what it accepts is within the documented ranges
// (docs/formats.md). The files a seed names exist as empty placeholders, so that inputs
// get past the file checks to the numbers.
#include <cmath>

#include "fuzz_input.h"
#include "lumar/base/error.h"
#include "lumar/scene/scene.h"

namespace {
bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lumar;
  static const bool placeholders = [] {
    for (const char* f : {"scenes/room/room.obj", "envmaps/interior.exr", "models/parasaurolophus_6700.ply",
                          "scenes/room/proxy.ply", "scenes/room/env.exr", "scenes/room/object.ply"})
      fuzz::write_file(fuzz::scratch() / f, "", 0);
    return true;
  }();
  (void)placeholders;
  const auto manifest = fuzz::input_file(data, size, "scenes/room/scene.json");
  try {
    const Scene scene = load_scene(manifest);
    FUZZ_CHECK(std::isfinite(scene.room_scale) && scene.room_scale > 0);
    FUZZ_CHECK(finite(scene.capture_position));
    FUZZ_CHECK(scene.room_scale >= kMinScale && scene.room_scale <= kMaxScale);
    for (const auto& object : scene.objects) {
      FUZZ_CHECK(finite(object.pose.translation));
      for (int a = 0; a < 3; ++a) FUZZ_CHECK(std::abs(object.pose.translation[a]) <= kMaxCoordinateM);
      FUZZ_CHECK(object.pose.scale >= kMinScale && object.pose.scale <= kMaxScale);
      FUZZ_CHECK(std::abs(glm::length(object.pose.rotation) - 1.0) < 1e-6);
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) FUZZ_CHECK(std::isfinite(object.T_world_model[c][r]));
      for (int k = 0; k < 3; ++k) FUZZ_CHECK(std::isfinite(object.albedo[k]));
    }
  } catch (const InputError&) {
  }
  return 0;
}
