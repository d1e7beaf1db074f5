#include "lumar/lighting/shadows/shadow_cone.h"

#include <cmath>

#include "cpu_clones.h"

namespace lumar {

ShadowCone::ShadowCone(const std::array<glm::vec3, 8>& corners, const glm::vec3& emitter, bool distant) {
  build(corners, emitter, distant);
}

LUMAR_AVX2_CLONES void ShadowCone::build(const std::array<glm::vec3, 8>& corners, const glm::vec3& emitter,
                                         bool distant) {
  const glm::vec3 centre = 0.5f * (corners[0] + corners[7]);
  const glm::vec3 edge[3] = {corners[1] - corners[0], corners[2] - corners[0], corners[4] - corners[0]};
  // Which face of each axis pair faces the emitter: +1 the + face, -1 the - face, 0 neither
  // (the emitter lies within that slab, or the light runs parallel to those faces).
  int facing[3];
  for (int a = 0; a < 3; ++a) {
    if (distant) {
      const float s = glm::dot(edge[a], emitter);
      facing[a] = s > 0.0f ? 1 : (s < 0.0f ? -1 : 0);
    } else {
      const float s = glm::dot(emitter - centre, edge[a]), half = 0.5f * glm::dot(edge[a], edge[a]);
      facing[a] = s > half ? 1 : (s < -half ? -1 : 0);
    }
  }
  if (!distant && facing[0] == 0 && facing[1] == 0 && facing[2] == 0) return;  // inside: everything
  // Silhouette: the edge along axis a at signs (sb, sc) of the other two axes b, c joins
  // faces (b, sb) and (c, sc); it is on the silhouette when exactly one of them faces the emitter.
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int sb = -1; sb <= 1; sb += 2)
      for (int sc = -1; sc <= 1; sc += 2) {
        if ((facing[b] == sb) == (facing[c] == sc)) continue;
        const glm::vec3 p = centre + 0.5f * (float(sb) * edge[b] + float(sc) * edge[c]);  // on the edge
        glm::vec3 n = distant ? glm::cross(edge[a], emitter) : glm::cross(edge[a], p - emitter);
        const float len = glm::length(n);
        if (!(len > 1e-20f)) continue;  // the emitter on the edge's line: dropping a plane only widens the cone
        n /= len;
        // A supporting plane of the box: the centre is on the inside.
        if (glm::dot(n, centre - p) > 0.0f) n = -n;
        planes_[std::size_t(count_++)] = glm::vec4(n, -glm::dot(n, p));
      }
  }
  // How far the box reaches along the viewing direction.
  const glm::vec3 d = distant ? emitter : glm::normalize(centre - emitter);
  float reach = 0.0f;
  for (const glm::vec3& e : edge) reach += 0.5f * std::abs(glm::dot(e, d));
  if (distant) {
    // A line from x runs along d: x beyond the box's far side cannot be shadowed by it.
    planes_[std::size_t(count_++)] = glm::vec4(d, -(glm::dot(centre, d) + reach));
  } else {
    // Receivers nearer the emitter than the box's nearest point cannot be shadowed by it.
    const float near = glm::dot(centre - emitter, d) - reach;
    if (near > 0.0f) planes_[std::size_t(count_++)] = glm::vec4(-d, glm::dot(d, emitter) + near);
  }
}

}  // namespace lumar
