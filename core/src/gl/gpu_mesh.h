#pragma once
// A Mesh in GPU buffers: positions at attribute 0, normals (if any) at attribute 1.
#include "gl/gl_util.h"
#include "lumar/core/mesh.h"

namespace lumar::gl {

class GpuMesh {
 public:
  GpuMesh() = default;
  // Throws InputError when `mesh` is inconsistent (index out of range, normal count
  // not matching positions, indices not a multiple of three). `what` names the mesh.
  GpuMesh(const Mesh& mesh, const char* what);

  bool empty() const { return index_count_ == 0; }
  void draw() const;  // binds its vertex array and draws the triangles

 private:
  GlName vertex_array_, positions_, normals_, indices_;
  GLsizei index_count_ = 0;
};

}  // namespace lumar::gl
