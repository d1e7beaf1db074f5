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

// The real SH basis, bands 0..2, at a unit direction, in the order 0 = L00, 1 = L1-1 (y),
// 2 = L10 (z), 3 = L11 (x), 4 = L2-2 (xy), 5 = L2-1 (yz), 6 = L20 (3z^2 - 1), 7 = L21 (xz),
// 8 = L22 (x^2 - y^2), with x, y, z the world axes as they are (+Y up). The GPU shader
// (core/render/src/shaders.cpp) evaluates the same order; keep them in step.
std::array<double, 9> sh9_basis(const glm::dvec3& d);

// Projects the map's radiance (in world directions) onto the 9 real SH basis functions,
// integrating every texel with its solid angle.
SH9 project_radiance_sh9(const EnvironmentMap& map);
// Irradiance E(n) = ∫ L(ω) max(0, n·ω) dω from the coefficients; a uniform map of
// radiance 1 gives π.
glm::dvec3 sh9_irradiance(const SH9& sh, const glm::dvec3& normal);

}  // namespace lumar
