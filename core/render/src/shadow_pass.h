#pragma once
// The receiver pass of the overlay: the receiver mesh (real surfaces that take shadows)
// drawn over the linear background, multiplying it by the per-vertex attenuation
// E_with / E_without (the ratio form of differential rendering, Debevec 1998), depth-tested
// against the proxy room so that hidden receivers leave the video alone. Drawn after the
// proxy depth and before the virtual objects. Private to core/render.
#include <glm/glm.hpp>
#include <span>

#include "gl_util.h"
#include "lumar/scene/mesh.h"

namespace lumar::gl {

class ShadowPass {
 public:
  ShadowPass();
  // World-space receiver mesh; attenuation starts at 1 (no shadow).
  void set_receivers(const Mesh& receivers_world);
  // One RGB attenuation per receiver vertex; throws InputError on a count mismatch.
  void set_attenuation(std::span<const glm::vec3> attenuation);
  bool empty() const { return index_count_ == 0; }
  // Multiplies the bound framebuffer's colour (depth test on, depth writes off).
  void draw(const glm::mat4& view_projection) const;

 private:
  GlName program_, vertex_array_, positions_, attenuation_, indices_;
  GLsizei index_count_ = 0;
  std::size_t vertex_count_ = 0;
};

}  // namespace lumar::gl
