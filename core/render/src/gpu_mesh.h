#pragma once
// A Mesh in GPU buffers: positions at attribute 0, normals (if any) at attribute 1, and
// optionally per-vertex values that change: a vec3 at attribute 2 (set_light_attenuation),
// a vec4 at attribute 3 (set_self_occlusion), a vec3 at attribute 4 (set_bounce_light), a
// vec3 at attribute 5 (set_vertex_irradiance) and a float at attribute 6
// (set_lights_blocked). Unset, attributes 3 to 6 read (0, 0, 0, 1).
// Objects also keep coarser versions of their triangles, to be drawn when small on screen.
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "gl_util.h"
#include "lumar/scene/mesh.h"

namespace lumar::gl {

class GpuMesh {
 public:
  GpuMesh() = default;
  // Throws InputError when `mesh` is inconsistent (index out of range, normal count
  // not matching positions, indices not a multiple of three). `what` names the mesh.
  // With levels, coarser versions of its triangles are kept beside them (mesh_levels.h).
  GpuMesh(const Mesh& mesh, const char* what, bool with_levels = false);

  bool empty() const { return levels_[0].count == 0; }
  // Per-vertex factor on the light (attribute 2); the first call creates its buffer.
  // Throws InputError unless there is one value per vertex.
  void set_light_attenuation(std::span<const glm::vec3> attenuation);
  // Per-vertex bent normal (xyz, model space) and open share (w) of the object's own
  // occlusion (lighting/self_occlusion.h). Same rules as set_light_attenuation.
  void set_self_occlusion(std::span<const glm::vec4> occlusion);
  // Per-vertex irradiance the other objects reflect onto it (attribute 4). Same rules.
  void set_bounce_light(std::span<const glm::vec3> irradiance);
  // Per-vertex irradiance that shades it instead of the per-pixel volume (attribute 5). Same rules.
  void set_vertex_irradiance(std::span<const glm::vec3> irradiance);
  // Per-vertex share of the exact lights the object blocks itself (attribute 6,
  // lighting/light_self_shadow.h). Same rules.
  void set_lights_blocked(std::span<const float> blocked);
  // Binds its vertex array and draws the triangles of `level` (0: the mesh as given).
  void draw(int level = 0) const;
  // The coarsest level whose surface is within `max_error` (model units) of the mesh's.
  int level_within(float max_error) const;
  std::size_t triangles(int level) const { return std::size_t(levels_[std::size_t(level)].count / 3); }

 private:
  void update_attribute(GlName& buffer, GLuint attribute, int components, const void* data, std::size_t count,
                        const char* what);
  GlName vertex_array_, positions_, normals_, indices_, attenuation_, occlusion_, bounce_, irradiance_, lights_blocked_;
  struct Level {
    GLsizei first = 0, count = 0;  // indices into the one index buffer
    float error = 0.0f;
  };
  std::vector<Level> levels_{Level{}};
  std::size_t vertex_count_ = 0;
};

}  // namespace lumar::gl
