#include "lumar/lighting/sh.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "lumar/base/constants.h"
#include "lumar/base/latlong.h"

namespace lumar {

namespace {

// Basis constants and R&H's c1..c5 in full double precision (R&H print them to six
// digits: 0.282095, 0.488603, 1.092548, 0.315392, 0.546274; c1 = 0.429043,
// c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708). Rounded constants
// break the exact rotation invariance of the band-2 terms at the 1e-6 level.
const double kY00 = 0.5 / std::sqrt(kPi);
const double kY1 = std::sqrt(3.0 / (4.0 * kPi));
const double kY2_offdiagonal = 0.5 * std::sqrt(15.0 / kPi);  // xy, yz, xz
const double kY20 = 0.25 * std::sqrt(5.0 / kPi);
const double kY22 = 0.25 * std::sqrt(15.0 / kPi);
// Convolution with the clamped cosine scales band l by A0 = pi, A1 = 2 pi / 3, A2 = pi / 4.
const double c1 = kPi / 4.0 * kY22;
const double c2 = 2.0 * kPi / 3.0 * kY1 / 2.0;
const double c3 = kPi / 4.0 * 3.0 * kY20;
const double c4 = kPi * kY00;
const double c5 = kPi / 4.0 * kY20;

}  // namespace

std::array<double, 9> sh9_basis(const glm::dvec3& d) {
  const double x = d.x, y = d.y, z = d.z;
  return {kY00,
          kY1 * y,
          kY1 * z,
          kY1 * x,
          kY2_offdiagonal * x * y,
          kY2_offdiagonal * y * z,
          kY20 * (3.0 * z * z - 1.0),
          kY2_offdiagonal * x * z,
          kY22 * (x * x - y * y)};
}

SH9 project_radiance_sh9(const EnvironmentMap& map) {
  // One partial sum per row, added in row order afterwards, so the result does not
  // depend on how TBB splits the rows.
  std::vector<SH9> rows(std::size_t(map.height));
  tbb::parallel_for(0, map.height, [&](int row) {
    const double solid_angle = latlong_pixel_solid_angle(row, map.width, map.height);
    SH9& sum = rows[std::size_t(row)];
    for (int col = 0; col < map.width; ++col) {
      const glm::dvec3 d = map.world_direction(latlong_pixel_direction(col, row, map.width, map.height));
      const glm::dvec3 L = glm::dvec3(map.texel(col, row)) * solid_angle;
      const auto Y = sh9_basis(d);
      for (int i = 0; i < 9; ++i) sum.coefficients[i] += L * Y[i];
    }
  });
  SH9 sh;
  for (const SH9& r : rows)
    for (int i = 0; i < 9; ++i) sh.coefficients[i] += r.coefficients[i];
  return sh;
}

glm::dvec3 sh9_irradiance(const SH9& sh, const glm::dvec3& normal) {
  // Ramamoorthi & Hanrahan 2001, equation 13.
  const auto& L = sh.coefficients;
  const double x = normal.x, y = normal.y, z = normal.z;
  return c1 * L[8] * (x * x - y * y) + c3 * L[6] * z * z + c4 * L[0] - c5 * L[6] +
         2.0 * c1 * (L[4] * x * y + L[7] * x * z + L[5] * y * z) + 2.0 * c2 * (L[3] * x + L[1] * y + L[2] * z);
}

}  // namespace lumar
