#pragma once
// The irradiance volume on the GPU: its arrays as textures (buffer textures for the
// probe table, node table and SH; 2D atlases for the octahedral maps) and the GLSL that
// evaluates it per pixel with the same arithmetic as IrradianceVolume::evaluate.
// Private to core/render.
#include "gl_util.h"
#include "lumar/lighting/irradiance_volume.h"

namespace lumar::gl {

// GLSL inserted after the shaded-object fragment shader's #version line (with_glsl_library):
// defines sh9_irradiance and
// vec3 volume_irradiance(vec3 p, vec3 n, vec3 n_lights, float rest_scale, float lights_scale). Texture units 8..15.
extern const char* const kIrradianceVolumeGlsl;

class IrradianceTextures {
 public:
  // Throws InputError when the volume has more lights than the shader takes.
  explicit IrradianceTextures(const IrradianceVolume& volume);
  // The same volume relit (IrradianceVolume::blend, relit_scene_lighting): uploads only
  // what light changes (irradiance atlas, SH, light radiance and visibility) in place.
  // False, changing nothing, when `volume`'s layout is not this one's.
  bool update_lighting(const IrradianceVolume& volume);
  // Sets the uniforms of `program` and binds the textures to their units.
  void bind(GLuint program) const;
  std::size_t bytes() const { return bytes_; }

 private:
  struct BufferTexture {
    GlName buffer, texture;
  };
  static BufferTexture buffer_texture(GLenum format, const void* data, std::size_t bytes, GLbitfield flags = 0);
  static GlName atlas(GLenum internal_format, GLenum format, int width, int height, const std::vector<float>& data);

  BufferTexture probes_, node_probe_, node_weight_, refined_, sh_, light_visibility_;
  GlName irradiance_, depth_;
  IrradianceVolume copy_;  // the uniforms' values (no arrays)
  int storage_ = 0, shadow_offset_ = 0, irradiance_width_ = 0, irradiance_height_ = 0;
  std::size_t probe_count_ = 0, sh_floats_ = 0;
  bool visibility_ = true, distant_ = false;
  std::size_t bytes_ = 0;
};

}  // namespace lumar::gl
