#pragma once
// Order-2 spherical harmonics (9 coefficients per colour channel) for irradiance,
// after Ramamoorthi & Hanrahan 2001. Good for smooth light; a small bright source
// does not fit in nine coefficients (see the irradiance-volume work for that).
#include <array>
#include <glm/glm.hpp>

#include "lumar/scene/envmap.h"

namespace lumar {

struct SH9 {
  std::array<glm::dvec3, 9> coefficients{};  // radiance projection L_lm, RGB, world frame
};

// Projects the map's radiance (in world directions) onto the 9 real SH basis functions,
// integrating every texel with its solid angle.
SH9 project_radiance_sh9(const EnvironmentMap& map);
// Irradiance E(n) = ∫ L(ω) max(0, n·ω) dω from the coefficients; a uniform map of
// radiance 1 gives π.
glm::dvec3 sh9_irradiance(const SH9& sh, const glm::dvec3& normal);

}  // namespace lumar
