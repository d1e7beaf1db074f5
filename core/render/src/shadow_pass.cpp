#include "shadow_pass.h"

#include <glm/gtc/type_ptr.hpp>
#include <string>
#include <vector>

#include "lumar/base/error.h"

namespace lumar::gl {

namespace {

const char* const kReceiverVertex = R"glsl(
#version 450 core
layout(location = 0) in vec3 position;
layout(location = 2) in vec3 attenuation;
uniform mat4 view_projection;
out vec3 vertex_attenuation;
void main() {
  vertex_attenuation = attenuation;
  gl_Position = view_projection * vec4(position, 1.0);
}
)glsl";

// Blending multiplies: destination * source. Above 1 is the light the objects reflect
// onto the receiver (the linear scene is a float target, so it is not clamped).
const char* const kReceiverFragment = R"glsl(
#version 450 core
in vec3 vertex_attenuation;
out vec4 color;
void main() { color = vec4(max(vertex_attenuation, 0.0), 1.0); }
)glsl";

}  // namespace

ShadowPass::ShadowPass() { program_ = create_program("shadow receivers", kReceiverVertex, kReceiverFragment); }

void ShadowPass::set_receivers(const Mesh& mesh) {
  index_count_ = 0;
  vertex_count_ = mesh.positions.size();
  for (std::uint32_t i : mesh.indices)
    if (i >= mesh.positions.size())
      throw InputError("shadow receivers: vertex index " + std::to_string(i) + " out of range; the mesh is corrupt");
  if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) return;
  vertex_array_ = create_vertex_array();
  const GLuint vao = vertex_array_.get();
  positions_ = create_buffer(mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3));
  attach_float_attribute(vao, 0, positions_.get(), 3);
  const std::vector<glm::vec3> ones(mesh.positions.size(), glm::vec3(1.0f));
  attenuation_ = create_buffer(ones.data(), ones.size() * sizeof(glm::vec3), GL_DYNAMIC_STORAGE_BIT);
  attach_float_attribute(vao, 2, attenuation_.get(), 3);
  indices_ = create_buffer(mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
  glVertexArrayElementBuffer(vao, indices_.get());
  index_count_ = GLsizei(mesh.indices.size());
  check_gl_errors("ShadowPass::set_receivers");
}

void ShadowPass::set_attenuation(std::span<const glm::vec3> attenuation) {
  if (attenuation.size() != vertex_count_)
    throw InputError("shadow receivers: " + std::to_string(attenuation.size()) + " attenuation values for " +
                     std::to_string(vertex_count_) + " receiver vertices; pass one per vertex");
  if (empty()) return;
  glNamedBufferSubData(attenuation_.get(), 0, GLsizeiptr(attenuation.size_bytes()), attenuation.data());
}

void ShadowPass::draw(const glm::mat4& view_projection) const {
  if (empty()) return;
  const GLuint p = program_.get();
  glUseProgram(p);
  glProgramUniformMatrix4fv(p, glGetUniformLocation(p, "view_projection"), 1, GL_FALSE,
                            glm::value_ptr(view_projection));
  // The receivers lie on the proxy: pull them slightly forward and test LEQUAL, so they
  // win against their own surface but not against nearer proxy geometry.
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(-1.0f, -4.0f);
  glEnable(GL_BLEND);
  glBlendFunc(GL_DST_COLOR, GL_ZERO);
  glBindVertexArray(vertex_array_.get());
  glDrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
  glDisable(GL_BLEND);
  glDisable(GL_POLYGON_OFFSET_FILL);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
}

}  // namespace lumar::gl
