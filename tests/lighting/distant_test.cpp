// Distant maps: the texel sum against analytic cases, and every representation against
// the texel sum on the four shared real HDR maps (2,000 random normals each).
#include <gtest/gtest.h>

#include <numbers>

#include "../common/test_paths.h"
#include "irradiance_test_util.h"
#include "lumar/base/constants.h"
#include "lumar/base/latlong.h"
#include "lumar/lighting/irradiance_reference.h"
#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/sh.h"

namespace lumar::test {
namespace {

EnvironmentMap uniform_map(int h, float value) {
  EnvironmentMap m;
  m.width = 2 * h, m.height = h;
  m.rgb.assign(std::size_t(m.width) * h * 3, value);
  return m;
}

TEST(IrradianceDistant, TexelSumOfAUniformMapIsPi) {
  const EnvironmentMap m = uniform_map(64, 1.0f);
  for (const glm::dvec3& n : random_normals(20, 1)) EXPECT_NEAR(luminance(texel_sum_irradiance(m, n)), kPi, 2e-3);
}

TEST(IrradianceDistant, TexelSumOfOneBrightTexelIsRadianceSolidAngleCosine) {
  EnvironmentMap m = uniform_map(64, 0.0f);
  const int col = 37, row = 21;
  m.azimuth_offset_deg = 30.0;
  for (int k = 0; k < 3; ++k) m.rgb[(std::size_t(row) * m.width + col) * 3 + k] = 500.0f;
  const double omega = latlong_pixel_solid_angle(row, m.width, m.height);
  const glm::dvec3 d = m.world_direction(latlong_pixel_direction(col, row, m.width, m.height));
  for (const glm::dvec3& n : random_normals(50, 2)) {
    const double expected = 500.0 * omega * std::max(0.0, glm::dot(n, d));
    EXPECT_NEAR(texel_sum_irradiance(m, n).g, expected, 1e-9 * 500.0);
  }
}

TEST(IrradianceDistant, EveryMethodGivesPiForAUniformMap) {
  const EnvironmentMap m = uniform_map(128, 1.0f);
  for (const char* method : {"volume", "sh9", "octahedral", "lights", "greger2004"}) {
    const VolumeSettings s = volume_settings_for(method);
    RoomRadiance radiance(m, s.radiance);
    const IrradianceVolume v = IrradianceVolume::build_distant(radiance, s);
    for (const glm::dvec3& n : random_normals(30, 3))
      EXPECT_NEAR(v.evaluate({0, 0, 0}, n).r, kPi, 0.01 * kPi) << method;
  }
}

// Acceptance: default settings within 1 % mean and 5 % at the 99th percentile on the
// real maps; SH9 measured beside it (it misses the suns).
TEST(IrradianceDistant, DefaultMeetsAccuracyOnTheSharedMapsAndSH9DoesNot) {
  const std::vector<glm::dvec3> normals = random_normals(2000, 7);
  for (const char* name : {"city", "courtyard", "interior", "studio"}) {
    const EnvironmentMap map = load_environment_map(shared_dir() / "data/envmaps" / (std::string(name) + ".exr"));
    const std::vector<glm::dvec3> reference = texel_sum_irradiance(map, normals);

    const VolumeSettings s = volume_settings_for("volume");
    RoomRadiance radiance(map, s.radiance);
    const IrradianceVolume v = IrradianceVolume::build_distant(radiance, s);
    std::vector<glm::dvec3> ours, sh;
    const SH9 coefficients = project_radiance_sh9(map);
    for (const glm::dvec3& n : normals) {
      ours.push_back(v.evaluate({0, 0, 0}, n));
      sh.push_back(glm::max(sh9_irradiance(coefficients, n), glm::dvec3(0.0)));
    }
    const ErrorStats e = luminance_errors(ours, reference), e_sh = luminance_errors(sh, reference);
    std::printf(
        "%-10s default (%s): mean %.3f %%, p99 %.3f %%, max %.2f %% | SH9: mean %.2f %%, p99 %.2f %%, max %.1f %% "
        "(%zu bright texels, %zu lights)\n",
        name, s.describe().c_str(), 100 * e.mean, 100 * e.p99, 100 * e.max, 100 * e_sh.mean, 100 * e_sh.p99,
        100 * e_sh.max, radiance.bright_texels().size(), radiance.lights().size());
    EXPECT_LE(e.mean, 0.01) << name;
    EXPECT_LE(e.p99, 0.05) << name;
    EXPECT_GT(e_sh.max, 0.2) << name;  // the reason for all this
  }
}

}  // namespace
}  // namespace lumar::test
