// Order-2 SH irradiance against analytic integrals and brute-force sums over the
// map's texels, the coefficient order shared with the GPU shader, the azimuth
// rotation, and the measured error on the four real HDR maps.
#include "lumar/lighting/sh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <random>

#include "lumar/base/color.h"
#include "lumar/base/constants.h"
#include "lumar/base/latlong.h"
#include "test_geometry.h"
#include "test_paths.h"

namespace lumar {
namespace {

// A map whose texel at map direction d is radiance(d), equal in R, G and B.
EnvironmentMap map_from(int width, const std::function<double(const glm::dvec3&)>& radiance) {
  EnvironmentMap map;
  map.width = width;
  map.height = width / 2;
  map.rgb.resize(std::size_t(map.width) * map.height * 3);
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < map.width; ++c) {
      const float v = float(radiance(latlong_pixel_direction(c, r, map.width, map.height)));
      for (int k = 0; k < 3; ++k) map.rgb[(std::size_t(r) * map.width + c) * 3 + k] = v;
    }
  return map;
}

// E(n) = sum over texels of L max(0, n . w) dOmega, in world directions.
class BruteForceIrradiance {
 public:
  explicit BruteForceIrradiance(const EnvironmentMap& map) {
    for (int r = 0; r < map.height; ++r) {
      const double solid_angle = latlong_pixel_solid_angle(r, map.width, map.height);
      for (int c = 0; c < map.width; ++c) {
        directions_.push_back(map.world_direction(latlong_pixel_direction(c, r, map.width, map.height)));
        weighted_.push_back(glm::dvec3(map.texel(c, r)) * solid_angle);
      }
    }
  }
  glm::dvec3 operator()(const glm::dvec3& n) const {
    glm::dvec3 sum(0.0);
    for (std::size_t i = 0; i < directions_.size(); ++i) {
      const double cosine = glm::dot(n, directions_[i]);
      if (cosine > 0.0) sum += weighted_[i] * cosine;
    }
    return sum;
  }

 private:
  std::vector<glm::dvec3> directions_, weighted_;
};

using test::random_normals;

TEST(SphericalHarmonics, UniformMapGivesPi) {
  const EnvironmentMap map = map_from(128, [](const glm::dvec3&) { return 1.0; });
  const SH9 sh = project_radiance_sh9(map);
  for (const auto& n : random_normals(20, 1)) {
    const glm::dvec3 E = sh9_irradiance(sh, n);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(E[k], kPi, 1e-3 * kPi) << n.x << " " << n.y << " " << n.z;
  }
}

TEST(SphericalHarmonics, CoefficientOrderMatchesTheShader) {
  // Projecting basis function j onto the basis gives the unit vector e_j, which pins
  // both the order (0 = L00, 1 = y, 2 = z, 3 = x, 4 = xy, 5 = yz, 6 = 3z^2-1, 7 = xz,
  // 8 = x^2-y^2) and the normalisation.
  const std::function<double(const glm::dvec3&)> basis[9] = {
      [](const glm::dvec3&) { return 0.282095; },
      [](const glm::dvec3& d) { return 0.488603 * d.y; },
      [](const glm::dvec3& d) { return 0.488603 * d.z; },
      [](const glm::dvec3& d) { return 0.488603 * d.x; },
      [](const glm::dvec3& d) { return 1.092548 * d.x * d.y; },
      [](const glm::dvec3& d) { return 1.092548 * d.y * d.z; },
      [](const glm::dvec3& d) { return 0.315392 * (3 * d.z * d.z - 1); },
      [](const glm::dvec3& d) { return 1.092548 * d.x * d.z; },
      [](const glm::dvec3& d) { return 0.546274 * (d.x * d.x - d.y * d.y); },
  };
  for (int j = 0; j < 9; ++j) {
    const SH9 sh = project_radiance_sh9(map_from(256, basis[j]));
    for (int i = 0; i < 9; ++i)
      EXPECT_NEAR(sh.coefficients[i].x, i == j ? 1.0 : 0.0, 2e-3) << "basis " << j << ", coefficient " << i;
  }
}

TEST(SphericalHarmonics, LinearRadianceIsExact) {
  // L = 1 + 0.5 w_y: E(n) = pi + 0.5 * (2 pi / 3) n_y, since the integral of
  // w max(0, n . w) over the sphere is (2 pi / 3) n.
  const EnvironmentMap map = map_from(256, [](const glm::dvec3& d) { return 1.0 + 0.5 * d.y; });
  const SH9 sh = project_radiance_sh9(map);
  for (const auto& n : random_normals(20, 2)) {
    const double expected = kPi + kPi / 3.0 * n.y;
    EXPECT_NEAR(sh9_irradiance(sh, n).x, expected, 1e-3 * expected);
  }
}

TEST(SphericalHarmonics, HemisphereStepIsExact) {
  // Sky-dome radiance 1 above the horizon: E(n) = pi (1 + n_y) / 2 exactly. The step
  // minus 1/2 is odd, so it has only odd bands, and the clamped cosine's A_l vanishes
  // for odd l > 1: the irradiance is exactly bands 0 and 1, so nine coefficients
  // reproduce it (only the texel sums differ).
  const EnvironmentMap map = map_from(256, [](const glm::dvec3& d) { return d.y > 0 ? 1.0 : 0.0; });
  const SH9 sh = project_radiance_sh9(map);
  const BruteForceIrradiance brute(map);
  double worst = 0.0;
  for (const auto& n : random_normals(50, 3)) {
    const double exact = kPi * (1 + n.y) / 2;
    EXPECT_NEAR(brute(n).x, exact, 2e-3) << "the brute-force reference itself";
    const double error = std::abs(sh9_irradiance(sh, n).x - exact);
    EXPECT_LE(error, 1e-3 * kPi);
    worst = std::max(worst, error);
  }
  std::printf("[ measured ] hemisphere step: worst |E_sh - E| = %.2e\n", worst);
}

TEST(SphericalHarmonics, SmallBrightCapWithinBound) {
  // A 15-degree cap of radiance 1 around an oblique direction: band 4 and up carry
  // real energy, so SH misses by a visible amount, bounded by R&H's 9 % of the peak.
  const glm::dvec3 centre = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
  const double cos_radius = std::cos(glm::radians(15.0));
  const EnvironmentMap map =
      map_from(512, [&](const glm::dvec3& d) { return glm::dot(d, centre) > cos_radius ? 1.0 : 0.0; });
  const SH9 sh = project_radiance_sh9(map);
  const BruteForceIrradiance brute(map);
  const double peak = brute(centre).x;
  // The cap edge cuts through texels, so the texel sum is off by a few tenths of a percent.
  EXPECT_NEAR(peak, kPi * (1 - cos_radius * cos_radius), 5e-3 * peak) << "a disc light: pi sin^2(radius)";
  double worst = 0.0;
  for (const auto& n : random_normals(100, 7)) worst = std::max(worst, std::abs(sh9_irradiance(sh, n).x - brute(n).x));
  std::printf("[ measured ] 15-degree cap: worst |E_sh - E_brute| = %.4f = %.2f%% of the peak %.4f\n", worst,
              100 * worst / peak, peak);
  EXPECT_LE(worst, 0.09 * peak);
  EXPECT_GT(worst, 0.01 * peak) << "a small source does not fit in nine coefficients";
}

TEST(SphericalHarmonics, CosineLobeMatchesBruteForce) {
  const EnvironmentMap map = map_from(256, [](const glm::dvec3& d) { return std::max(0.0, d.y); });
  const SH9 sh = project_radiance_sh9(map);
  const BruteForceIrradiance brute(map);
  EXPECT_NEAR(brute({0, 1, 0}).x, 2 * kPi / 3, 1e-3) << "integral of cos^2 over the upper hemisphere";
  double worst = 0.0;
  for (const auto& n : random_normals(50, 4)) {
    const double error = std::abs(sh9_irradiance(sh, n).x - brute(n).x);
    EXPECT_LE(error, 0.1 * kPi);
    worst = std::max(worst, error);
  }
  EXPECT_GT(worst, 1e-3) << "the lobe's band 4 is not zero, so SH is not exact";
  std::printf("[ measured ] cosine lobe: worst |E_sh - E_brute| = %.4f\n", worst);
}

TEST(SphericalHarmonics, AzimuthOffsetRotatesTheResult) {
  // Analytic: L = 1 + 0.5 x_map and world = Ry(90) map, so x_map = -z_world and
  // E(n) = pi - (pi / 3) n_z.
  EnvironmentMap linear = map_from(256, [](const glm::dvec3& d) { return 1.0 + 0.5 * d.x; });
  linear.azimuth_offset_deg = 90.0;
  const SH9 sh_linear = project_radiance_sh9(linear);
  for (const auto& n : random_normals(10, 5)) {
    const double expected = kPi - kPi / 3.0 * n.z;
    EXPECT_NEAR(sh9_irradiance(sh_linear, n).x, expected, 1e-3 * expected);
  }

  // Any map: E with offset a at Ry(a) n equals E without offset at n.
  EnvironmentMap map = load_environment_map(test::shared_dir() / "data/envmaps/city.exr");
  const SH9 sh0 = project_radiance_sh9(map);
  map.azimuth_offset_deg = 37.0;
  const SH9 sh37 = project_radiance_sh9(map);
  for (const auto& n : random_normals(20, 6)) {
    const glm::dvec3 a = sh9_irradiance(sh0, n), b = sh9_irradiance(sh37, map.world_direction(n));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(b[k], a[k], 1e-9 * std::abs(a[k]) + 1e-12);
  }
  // ... and a rotation actually changes the coefficients for a map with structure.
  EXPECT_GT(glm::distance(sh0.coefficients[3], sh37.coefficients[3]), 1e-3 * glm::length(sh0.coefficients[0]));
}

TEST(SphericalHarmonics, ErrorOnRealMaps) {
  // Fibonacci-sphere normals, relative error in luminance against the brute-force sum.
  const int count = 200;
  std::vector<glm::dvec3> normals;
  for (int i = 0; i < count; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / count, r = std::sqrt(1 - y * y);
    const double phi = i * kPi * (3.0 - std::sqrt(5.0));
    normals.emplace_back(r * std::cos(phi), y, r * std::sin(phi));
  }
  for (const char* name : {"city", "courtyard", "interior", "studio"}) {
    const EnvironmentMap map = load_environment_map(test::shared_dir() / "data/envmaps" / (std::string(name) + ".exr"));
    const SH9 sh = project_radiance_sh9(map);
    const BruteForceIrradiance brute(map);
    double sum = 0.0, worst = 0.0;
    for (const auto& n : normals) {
      const double reference = luminance(brute(n));
      ASSERT_GT(reference, 0.0) << name;
      const double error = std::abs(luminance(sh9_irradiance(sh, n)) - reference) / reference;
      sum += error;
      worst = std::max(worst, error);
    }
    const double mean = sum / count;
    std::printf("[ measured ] %-9s order-2 SH irradiance error over %d normals: mean %.2f%%, worst %.2f%%\n", name,
                count, 100 * mean, 100 * worst);
    EXPECT_LT(mean, 0.20) << name;
    EXPECT_LT(worst, 1.0) << name;
    EXPECT_GT(worst, 0.01) << name << ": a small bright source does not fit in nine coefficients";
  }
}

}  // namespace
}  // namespace lumar
