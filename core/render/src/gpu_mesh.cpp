#include "gpu_mesh.h"

#include <string>

#include "lumar/base/error.h"
#include "mesh_levels.h"

namespace lumar::gl {

GpuMesh::GpuMesh(const Mesh& mesh, const char* what, bool with_levels) {
  if (mesh.indices.size() % 3 != 0)
    throw InputError(std::string(what) + ": index count is not a multiple of three; pass whole triangles");
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
    throw InputError(std::string(what) + ": " + std::to_string(mesh.normals.size()) + " normals for " +
                     std::to_string(mesh.positions.size()) + " positions; give one normal per vertex");
  for (std::uint32_t i : mesh.indices)
    if (i >= mesh.positions.size())
      throw InputError(std::string(what) + ": vertex index " + std::to_string(i) + " out of range (" +
                       std::to_string(mesh.positions.size()) + " vertices); the mesh is corrupt");
  if (mesh.indices.empty()) return;

  vertex_array_ = create_vertex_array();
  const GLuint vao = vertex_array_.get();
  positions_ = create_buffer(mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3));
  attach_float_attribute(vao, 0, positions_.get(), 3);
  if (!mesh.normals.empty()) {
    normals_ = create_buffer(mesh.normals.data(), mesh.normals.size() * sizeof(glm::vec3));
    attach_float_attribute(vao, 1, normals_.get(), 3);
  }
  // Every level's triangles one after another in one buffer.
  std::vector<std::uint32_t> indices;
  levels_.clear();
  for (const MeshLevel& level : with_levels ? mesh_levels(mesh) : std::vector<MeshLevel>{{mesh.indices, 0.0f}}) {
    levels_.push_back({GLsizei(indices.size()), GLsizei(level.indices.size()), level.error});
    indices.insert(indices.end(), level.indices.begin(), level.indices.end());
  }
  indices_ = create_buffer(indices.data(), indices.size() * sizeof(std::uint32_t));
  glVertexArrayElementBuffer(vao, indices_.get());
  vertex_count_ = mesh.positions.size();
}

// One float attribute per vertex that changes: its buffer is made on the first call.
void GpuMesh::update_attribute(GlName& buffer, GLuint attribute, int components, const void* data, std::size_t count,
                               const char* what) {
  if (count != vertex_count_)
    throw InputError(std::to_string(count) + " " + what + " values for a mesh of " + std::to_string(vertex_count_) +
                     " vertices; pass one per vertex");
  if (empty()) return;
  const std::size_t bytes = count * std::size_t(components) * sizeof(float);
  if (!buffer) {
    buffer = create_buffer(data, bytes, GL_DYNAMIC_STORAGE_BIT);
    attach_float_attribute(vertex_array_.get(), attribute, buffer.get(), components);
  } else {
    glNamedBufferSubData(buffer.get(), 0, GLsizeiptr(bytes), data);
  }
}

void GpuMesh::set_light_attenuation(std::span<const glm::vec3> attenuation) {
  update_attribute(attenuation_, 2, 3, attenuation.data(), attenuation.size(), "light attenuation");
}

void GpuMesh::set_self_occlusion(std::span<const glm::vec4> occlusion) {
  update_attribute(occlusion_, 3, 4, occlusion.data(), occlusion.size(), "self-occlusion");
}

void GpuMesh::set_bounce_light(std::span<const glm::vec3> irradiance) {
  update_attribute(bounce_, 4, 3, irradiance.data(), irradiance.size(), "bounce light");
}

void GpuMesh::set_vertex_irradiance(std::span<const glm::vec3> irradiance) {
  update_attribute(irradiance_, 5, 3, irradiance.data(), irradiance.size(), "vertex irradiance");
}

void GpuMesh::set_lights_blocked(std::span<const float> blocked) {
  update_attribute(lights_blocked_, 6, 1, blocked.data(), blocked.size(), "light self-shadow");
}

void GpuMesh::draw(int level) const {
  if (empty()) return;
  const Level& l = levels_[std::size_t(level)];
  glBindVertexArray(vertex_array_.get());
  glDrawElements(GL_TRIANGLES, l.count, GL_UNSIGNED_INT,
                 reinterpret_cast<const void*>(std::uintptr_t(l.first) * sizeof(std::uint32_t)));
}

int GpuMesh::level_within(float max_error) const {
  int level = 0;
  while (level + 1 < int(levels_.size()) && levels_[std::size_t(level + 1)].error <= max_error) ++level;
  return level;
}

}  // namespace lumar::gl
