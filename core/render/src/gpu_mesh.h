#pragma once
// A Mesh in GPU buffers: positions at attribute 0, normals (if any) at attribute 1, and
// optionally one more per-vertex vec3 that changes (set_light_attenuation) at attribute 2.
#include <glm/glm.hpp>
#include <span>

#include "gl_util.h"
#include "lumar/scene/mesh.h"

namespace lumar::gl {

class GpuMesh {
 public:
  GpuMesh() = default;
  // Throws InputError when `mesh` is inconsistent (index out of range, normal count
  // not matching positions, indices not a multiple of three). `what` names the mesh.
  GpuMesh(const Mesh& mesh, const char* what);

  bool empty() const { return index_count_ == 0; }
  // Per-vertex factor on the light (attribute 2); the first call creates its buffer.
  // Throws InputError unless there is one value per vertex.
  void set_light_attenuation(std::span<const glm::vec3> attenuation);
  void draw() const;  // binds its vertex array and draws the triangles

 private:
  GlName vertex_array_, positions_, normals_, indices_, attenuation_;
  GLsizei index_count_ = 0;
  std::size_t vertex_count_ = 0;
};

}  // namespace lumar::gl
