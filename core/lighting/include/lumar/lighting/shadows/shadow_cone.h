#pragma once
// The shadow cone of a box seen from one emitter point: every receiver whose line to the
// point may cross the box lies inside it. Bounded by the planes through the emitter point
// and the box's silhouette edges (the edges between a face turned towards the point and
// one turned away; for a distant light, planes along the light's direction), and by one
// more plane that drops receivers nearer the emitter than the box (distant: beyond it).
// Built per frame, emitter point and box, so it must be cheap: no projection, no hull.
#include <array>
#include <glm/glm.hpp>

namespace lumar {

class ShadowCone {
 public:
  static constexpr int kMaxPlanes = 7;  // a box's silhouette has at most 6 edges

  // `corners`: the box (orthogonal edges E_a, any orientation), corner k = centre + sum
  // over axes a of +-E_a / 2, the sign given by bit a of k. `emitter`: the emitter point, or for a distant
  // light the unit direction towards it (lines run from the receiver along it).
  // An emitter point inside the box gives a cone that contains everything.
  ShadowCone(const std::array<glm::vec3, 8>& corners, const glm::vec3& emitter, bool distant);

  // Whether a line from x to the emitter may cross the box (false: it certainly does not).
  bool contains(const glm::vec3& x) const {
    for (int i = 0; i < count_; ++i)
      if (glm::dot(glm::vec3(planes_[std::size_t(i)]), x) + planes_[std::size_t(i)].w > kMargin) return false;
    return true;
  }
  bool everything() const { return count_ == 0; }
  int plane_count() const { return count_; }
  // Unit normal (xyz) and offset (w): inside where dot(n, x) + w <= kMargin.
  const glm::vec4& plane(int i) const { return planes_[std::size_t(i)]; }

  // Floating-point slack (metres): a receiver this near the cone's boundary counts as inside.
  static constexpr float kMargin = 1e-4f;

 private:
  void build(const std::array<glm::vec3, 8>& corners, const glm::vec3& emitter, bool distant);
  std::array<glm::vec4, kMaxPlanes> planes_;
  int count_ = 0;
};

}  // namespace lumar
