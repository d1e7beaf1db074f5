#include "irradiance_textures.h"

#include <glm/gtc/type_ptr.hpp>

#include "lumar/base/error.h"

namespace lumar::gl {

const char* const kIrradianceVolumeGlsl = R"glsl(
layout(binding = 8) uniform samplerBuffer volume_probes;         // xyz, enabled
layout(binding = 9) uniform isamplerBuffer volume_node_probe;    // 4 probe indices per fine node
layout(binding = 10) uniform samplerBuffer volume_node_weight;    // their weights
layout(binding = 11) uniform isamplerBuffer volume_refined;      // per cell
layout(binding = 12) uniform sampler2D volume_irradiance_atlas;  // RGB, (n+2)^2 per probe
layout(binding = 13) uniform sampler2D volume_depth_atlas;       // RG moments
layout(binding = 14) uniform samplerBuffer volume_sh;            // 9 RGBA texels per probe
layout(binding = 15) uniform samplerBuffer volume_light_visibility;  // then the light shadow maps
uniform int volume_shadow_n, volume_shadow_offset;
uniform vec3 volume_box_min, volume_cell_size, volume_capture;
uniform ivec3 volume_cells;
uniform int volume_storage, volume_irradiance_n, volume_depth_n, volume_columns, volume_light_count;
uniform float volume_normal_bias;
uniform bool volume_visibility, volume_distant;
uniform vec4 volume_light_radiance[16];   // rgb, solid angle from the capture point
uniform vec4 volume_light_direction[16];  // xyz, on_proxy
uniform vec3 volume_light_position[16];
uniform vec3 volume_light_normal[16];

float volume_sign(float v) { return v >= 0.0 ? 1.0 : -1.0; }

vec2 volume_oct_encode(vec3 d) {
  float l1 = abs(d.x) + abs(d.y) + abs(d.z);
  vec2 e = vec2(d.x, d.z) / l1;
  if (d.y < 0.0) e = vec2((1.0 - abs(e.y)) * volume_sign(e.x), (1.0 - abs(e.x)) * volume_sign(e.y));
  return e;
}

vec4 volume_sample_block(sampler2D atlas, int n, int probe, vec2 e) {
  ivec2 b = ivec2((probe % volume_columns) * (n + 2), (probe / volume_columns) * (n + 2));
  vec2 x = 1.0 + (e * 0.5 + 0.5) * float(n) - 0.5;
  ivec2 x0 = clamp(ivec2(floor(x)), ivec2(0), ivec2(n));
  vec2 f = clamp(x - vec2(x0), 0.0, 1.0);
  vec4 a = texelFetch(atlas, b + x0, 0), c = texelFetch(atlas, b + x0 + ivec2(1, 0), 0);
  vec4 d = texelFetch(atlas, b + x0 + ivec2(0, 1), 0), g = texelFetch(atlas, b + x0 + ivec2(1, 1), 0);
  return mix(mix(a, c, f.x), mix(d, g, f.x), f.y);
}

// Ramamoorthi & Hanrahan 2001, eq. 13: irradiance at world normal n from nine SH
// coefficients in sh9_basis's order (lighting/sh.h); the shaded-object shader uses it too.
vec3 sh9_irradiance(vec3 L0, vec3 L1, vec3 L2, vec3 L3, vec3 L4, vec3 L5, vec3 L6, vec3 L7, vec3 L8, vec3 n) {
  const float c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708;
  float x = n.x, y = n.y, z = n.z;
  return c1 * L8 * (x * x - y * y) + c3 * L6 * z * z + c4 * L0 - c5 * L6 +
         2.0 * c1 * (L4 * x * y + L7 * x * z + L5 * y * z) + 2.0 * c2 * (L3 * x + L1 * y + L2 * z);
}

vec3 volume_probe_irradiance(int k, vec3 n) {
  vec3 e = vec3(0.0);
  if (volume_storage != 1) {
    // Plain locals, not an array: software rasterisers spill indexed arrays to memory.
    int b = k * 9;
    vec3 L0 = texelFetch(volume_sh, b).rgb, L1 = texelFetch(volume_sh, b + 1).rgb, L2 = texelFetch(volume_sh, b + 2).rgb;
    vec3 L3 = texelFetch(volume_sh, b + 3).rgb, L4 = texelFetch(volume_sh, b + 4).rgb, L5 = texelFetch(volume_sh, b + 5).rgb;
    vec3 L6 = texelFetch(volume_sh, b + 6).rgb, L7 = texelFetch(volume_sh, b + 7).rgb, L8 = texelFetch(volume_sh, b + 8).rgb;
    e = sh9_irradiance(L0, L1, L2, L3, L4, L5, L6, L7, L8, n);
  }
  if (volume_storage != 0)
    e += volume_sample_block(volume_irradiance_atlas, volume_irradiance_n, k, volume_oct_encode(n)).rgb;
  return max(e, vec3(0.0));
}

float volume_shadow_lit(int base, int i, int j, float limit) {
  return texelFetch(volume_light_visibility, base + j * volume_shadow_n + i).r >= limit ? 1.0 : 0.0;
}

// IrradianceVolume::light_shadow_visibility.
float volume_light_shadow(int l, vec3 p) {
  vec3 v = p - volume_light_position[l];
  float r = length(v);
  if (r < 1e-9) return 1.0;
  int n = volume_shadow_n;
  vec2 e = volume_oct_encode(v / r);
  vec2 x = (e * 0.5 + 0.5) * float(n) - 0.5;
  ivec2 x0 = clamp(ivec2(floor(x)), ivec2(0), ivec2(n - 2));
  vec2 f = clamp(x - vec2(x0), 0.0, 1.0);
  float limit = r - 0.02 - 0.02 * r;
  int base = volume_shadow_offset + l * n * n;
  float a = volume_shadow_lit(base, x0.x, x0.y, limit), b = volume_shadow_lit(base, x0.x + 1, x0.y, limit);
  float c = volume_shadow_lit(base, x0.x, x0.y + 1, limit), d = volume_shadow_lit(base, x0.x + 1, x0.y + 1, limit);
  return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// IrradianceVolume::evaluate: the probes' light at n times rest_scale, plus the exact
// lights at n_lights times lights_scale.
vec3 volume_irradiance(vec3 p, vec3 n, vec3 n_lights, float rest_scale, float lights_scale) {
  float light_weight[16];
  for (int l = 0; l < 16; ++l) light_weight[l] = 0.0;
  vec3 sum = vec3(0.0);
  float total = 0.0;
  if (volume_distant) {
    sum = volume_probe_irradiance(0, n);
    total = 1.0;
    for (int l = 0; l < volume_light_count; ++l) light_weight[l] = texelFetch(volume_light_visibility, l).r;
  } else {
    vec3 local = clamp((p - volume_box_min) / volume_cell_size, vec3(0.0), vec3(volume_cells) - 1e-4);
    ivec3 cell = clamp(ivec3(floor(local)), ivec3(0), volume_cells - 1);
    vec3 t = local - vec3(cell);
    ivec3 base = 2 * cell;
    int stride = 2;
    if (texelFetch(volume_refined, (cell.z * volume_cells.y + cell.y) * volume_cells.x + cell.x).r != 0) {
      ivec3 half_ = ivec3(greaterThanEqual(t, vec3(0.5)));
      base += half_;
      t = t * 2.0 - vec3(half_);
      stride = 1;
    }
    ivec3 F = 2 * volume_cells + 1;
    vec3 biased = p + n * volume_normal_bias;
    for (int corner = 0; corner < 8; ++corner) {
      ivec3 o = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
      ivec3 I = base + o * stride;
      float tri = (o.x != 0 ? t.x : 1.0 - t.x) * (o.y != 0 ? t.y : 1.0 - t.y) * (o.z != 0 ? t.z : 1.0 - t.z);
      if (tri <= 0.0) continue;
      int node = (I.z * F.y + I.y) * F.x + I.x;
      ivec4 ks = texelFetch(volume_node_probe, node);
      vec4 ws = texelFetch(volume_node_weight, node);
      for (int e = 0; e < 4; ++e) {
        int k = ks[e];
        if (k < 0) continue;
        vec4 probe = texelFetch(volume_probes, k);
        if (probe.w == 0.0) continue;
        float w = tri * ws[e];
        if (volume_visibility) {
          vec3 to_probe = probe.xyz - p;
          float d = length(to_probe);
          float vis = d > 1e-9 ? dot(to_probe / d, n) * 0.5 + 0.5 : 1.0;
          vis = vis * vis + 0.2;
          vec3 from_probe = biased - probe.xyz;
          float r = length(from_probe);
          if (r > 1e-9) {
            vec2 m = volume_sample_block(volume_depth_atlas, volume_depth_n, k, volume_oct_encode(from_probe / r)).rg;
            if (r > m.x) {
              float variance = abs(m.y - m.x * m.x);
              float chebyshev = variance / (variance + (r - m.x) * (r - m.x));
              vis *= max(chebyshev * chebyshev * chebyshev, 0.0);
            }
          }
          vis = max(vis, 1e-6);
          if (vis < 0.2) vis *= vis * vis / 0.04;
          w *= vis;
        }
        sum += w * volume_probe_irradiance(k, n);
        for (int l = 0; l < volume_light_count; ++l)
          if (volume_shadow_n == 0 || volume_light_direction[l].w == 0.0)  // else its shadow map decides
            light_weight[l] += w * texelFetch(volume_light_visibility, k * volume_light_count + l).r;
        total += w;
      }
    }
  }
  if (total <= 0.0) return vec3(0.0);
  vec3 exact = vec3(0.0);
  for (int l = 0; l < volume_light_count; ++l) {
    bool mapped = volume_shadow_n > 0 && volume_light_direction[l].w != 0.0;
    float visibility = mapped ? volume_light_shadow(l, p) : light_weight[l] / total;
    if (visibility <= 0.0) continue;
    vec3 toward = volume_light_direction[l].xyz;
    float omega = volume_light_radiance[l].w;
    if (volume_light_direction[l].w != 0.0) {  // on the proxy: patch_solid_angle_from (room_radiance.h)
      vec3 v = p - volume_light_position[l];
      float r2 = dot(v, v);
      if (r2 < 1e-12) continue;
      float r = sqrt(r2);
      toward = -v / r;
      float cos_p = dot(volume_light_normal[l], v) / r;
      if (cos_p <= 0.0) continue;
      vec3 vc = volume_capture - volume_light_position[l];
      float rc2 = dot(vc, vc);
      float cos_c = max(dot(volume_light_normal[l], vc) / sqrt(rc2), 1e-3);
      omega = min(omega * rc2 / r2 * cos_p / cos_c, 6.28318530717959);
    }
    float cosine = dot(n_lights, toward);
    if (omega > 0.0 && cosine > 0.0) exact += visibility * volume_light_radiance[l].rgb * omega * cosine;
  }
  return rest_scale * (sum / total) + lights_scale * exact;
}
)glsl";

IrradianceTextures::BufferTexture IrradianceTextures::buffer_texture(GLenum format, const void* data, std::size_t bytes,
                                                                     GLbitfield flags) {
  BufferTexture t;
  static const float zero[4] = {0, 0, 0, 0};
  t.buffer = create_buffer(bytes ? data : zero, bytes ? bytes : sizeof(zero), flags);
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_BUFFER, 1, &id);
  t.texture = GlName(id, [](GLuint n) { glDeleteTextures(1, &n); });
  glTextureBuffer(id, format, t.buffer.get());
  return t;
}

GlName IrradianceTextures::atlas(GLenum internal_format, GLenum format, int width, int height,
                                 const std::vector<float>& data) {
  GlName t = create_texture_2d(internal_format, std::max(width, 1), std::max(height, 1), GL_NEAREST, GL_CLAMP_TO_EDGE,
                               GL_CLAMP_TO_EDGE);
  if (!data.empty()) {
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTextureSubImage2D(t.get(), 0, 0, 0, width, height, format, GL_FLOAT, data.data());
  }
  return t;
}

IrradianceTextures::IrradianceTextures(const IrradianceVolume& v) {
  if (v.lights.size() > std::size_t(kMaxExactLights))
    throw InputError("irradiance volume has " + std::to_string(v.lights.size()) +
                     " lights; the GPU path takes at most " + std::to_string(kMaxExactLights) +
                     " (lower lighting.irradiance.max_lights)");
  probes_ = buffer_texture(GL_RGBA32F, v.probes.data(), v.probes.size() * sizeof(glm::vec4));
  node_probe_ = buffer_texture(GL_RGBA32I, v.node_probe.data(), v.node_probe.size() * sizeof(std::array<int, 4>));
  node_weight_ = buffer_texture(GL_RGBA32F, v.node_weight.data(), v.node_weight.size() * sizeof(std::array<float, 4>));
  std::vector<int> refined(v.refined.begin(), v.refined.end());
  refined_ = buffer_texture(GL_R32I, refined.data(), refined.size() * sizeof(int));
  std::vector<float> sh_rgba(v.sh.size() / 3 * 4, 0.0f);  // one RGBA texel per coefficient: 9 fetches, not 27
  for (std::size_t i = 0; i < v.sh.size() / 3; ++i)
    for (int c = 0; c < 3; ++c) sh_rgba[i * 4 + std::size_t(c)] = v.sh[i * 3 + std::size_t(c)];
  // The light's own (SH, visibility) may be updated in place when the room is relit.
  sh_ = buffer_texture(GL_RGBA32F, sh_rgba.data(), sh_rgba.size() * sizeof(float), GL_DYNAMIC_STORAGE_BIT);
  std::vector<float> visibility_and_shadows = v.light_visibility;
  visibility_and_shadows.insert(visibility_and_shadows.end(), v.light_shadow.begin(), v.light_shadow.end());
  light_visibility_ = buffer_texture(GL_R32F, visibility_and_shadows.data(),
                                     visibility_and_shadows.size() * sizeof(float), GL_DYNAMIC_STORAGE_BIT);
  shadow_offset_ = int(v.light_visibility.size());
  const bool has_irradiance = !v.irradiance_atlas.empty();
  irradiance_ = atlas(GL_RGB32F, GL_RGB, has_irradiance ? v.atlas_width(v.irradiance_n) : 1,
                      has_irradiance ? v.atlas_height(v.irradiance_n) : 1, v.irradiance_atlas);
  const bool has_depth = !v.depth_atlas.empty();
  depth_ = atlas(GL_RG32F, GL_RG, has_depth ? v.atlas_width(v.depth_n) : 1, has_depth ? v.atlas_height(v.depth_n) : 1,
                 v.depth_atlas);
  copy_.box_min = v.box_min, copy_.cell_size = v.cell_size, copy_.cells = v.cells;
  copy_.capture_position = v.capture_position, copy_.irradiance_n = v.irradiance_n, copy_.depth_n = v.depth_n;
  copy_.atlas_columns = v.atlas_columns, copy_.normal_bias = v.normal_bias, copy_.lights = v.lights;
  copy_.shadow_n = v.shadow_n;
  irradiance_width_ = has_irradiance ? v.atlas_width(v.irradiance_n) : 0;
  irradiance_height_ = has_irradiance ? v.atlas_height(v.irradiance_n) : 0;
  probe_count_ = v.probes.size();
  sh_floats_ = v.sh.size();
  storage_ = int(v.settings().storage);
  visibility_ = v.settings().visibility;
  distant_ = v.distant();
  bytes_ = (v.probes.size() * 4 + v.node_probe.size() * 8 + refined.size() + v.sh.size() + v.light_visibility.size() +
            v.light_shadow.size() + v.irradiance_atlas.size() + v.depth_atlas.size()) *
           4;
  check_gl_errors("IrradianceTextures");
}

bool IrradianceTextures::update_lighting(const IrradianceVolume& v) {
  const bool has_irradiance = !v.irradiance_atlas.empty();
  if (v.probes.size() != probe_count_ || v.sh.size() != sh_floats_ || v.lights.size() != copy_.lights.size() ||
      int(v.light_visibility.size()) != shadow_offset_ ||
      (has_irradiance ? v.atlas_width(v.irradiance_n) : 0) != irradiance_width_ ||
      (has_irradiance ? v.atlas_height(v.irradiance_n) : 0) != irradiance_height_ || v.box_min != copy_.box_min ||
      v.cell_size != copy_.cell_size || v.cells != copy_.cells || v.capture_position != copy_.capture_position)
    return false;
  for (std::size_t l = 0; l < v.lights.size(); ++l)
    if (v.lights[l].position != copy_.lights[l].position || v.lights[l].direction != copy_.lights[l].direction)
      return false;
  if (!v.sh.empty()) {
    std::vector<float> sh_rgba(v.sh.size() / 3 * 4, 0.0f);
    for (std::size_t i = 0; i < v.sh.size() / 3; ++i)
      for (int c = 0; c < 3; ++c) sh_rgba[i * 4 + std::size_t(c)] = v.sh[i * 3 + std::size_t(c)];
    glNamedBufferSubData(sh_.buffer.get(), 0, GLsizeiptr(sh_rgba.size() * sizeof(float)), sh_rgba.data());
  }
  if (!v.light_visibility.empty())
    glNamedBufferSubData(light_visibility_.buffer.get(), 0, GLsizeiptr(v.light_visibility.size() * sizeof(float)),
                         v.light_visibility.data());
  if (has_irradiance) {
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTextureSubImage2D(irradiance_.get(), 0, 0, 0, irradiance_width_, irradiance_height_, GL_RGB, GL_FLOAT,
                        v.irradiance_atlas.data());
  }
  copy_.lights = v.lights;
  check_gl_errors("IrradianceTextures::update_lighting");
  return true;
}

void IrradianceTextures::bind(GLuint p) const {
  const auto u = [&](const char* name) { return glGetUniformLocation(p, name); };
  glProgramUniform3fv(p, u("volume_box_min"), 1, glm::value_ptr(glm::vec3(copy_.box_min)));
  glProgramUniform3fv(p, u("volume_cell_size"), 1, glm::value_ptr(glm::vec3(copy_.cell_size)));
  glProgramUniform3fv(p, u("volume_capture"), 1, glm::value_ptr(glm::vec3(copy_.capture_position)));
  glProgramUniform3i(p, u("volume_cells"), copy_.cells.x, copy_.cells.y, copy_.cells.z);
  glProgramUniform1i(p, u("volume_storage"), storage_);
  glProgramUniform1i(p, u("volume_irradiance_n"), copy_.irradiance_n);
  glProgramUniform1i(p, u("volume_depth_n"), copy_.depth_n);
  glProgramUniform1i(p, u("volume_columns"), copy_.atlas_columns);
  glProgramUniform1i(p, u("volume_light_count"), int(copy_.lights.size()));
  glProgramUniform1f(p, u("volume_normal_bias"), float(copy_.normal_bias));
  glProgramUniform1i(p, u("volume_shadow_n"), copy_.shadow_n);
  glProgramUniform1i(p, u("volume_shadow_offset"), shadow_offset_);
  glProgramUniform1i(p, u("volume_visibility"), visibility_ ? 1 : 0);
  glProgramUniform1i(p, u("volume_distant"), distant_ ? 1 : 0);
  std::vector<glm::vec4> radiance, direction;
  std::vector<glm::vec3> position, normal;
  for (const VolumeLight& l : copy_.lights) {
    radiance.emplace_back(glm::vec3(l.radiance), float(l.solid_angle));
    direction.emplace_back(glm::vec3(l.direction), l.on_proxy ? 1.0f : 0.0f);
    position.emplace_back(l.position);
    normal.emplace_back(l.normal);
  }
  if (!copy_.lights.empty()) {
    const auto n = GLsizei(copy_.lights.size());
    glProgramUniform4fv(p, u("volume_light_radiance"), n, glm::value_ptr(radiance[0]));
    glProgramUniform4fv(p, u("volume_light_direction"), n, glm::value_ptr(direction[0]));
    glProgramUniform3fv(p, u("volume_light_position"), n, glm::value_ptr(position[0]));
    glProgramUniform3fv(p, u("volume_light_normal"), n, glm::value_ptr(normal[0]));
  }
  glBindTextureUnit(8, probes_.texture.get());
  glBindTextureUnit(9, node_probe_.texture.get());
  glBindTextureUnit(10, node_weight_.texture.get());
  glBindTextureUnit(11, refined_.texture.get());
  glBindTextureUnit(12, irradiance_.get());
  glBindTextureUnit(13, depth_.get());
  glBindTextureUnit(14, sh_.texture.get());
  glBindTextureUnit(15, light_visibility_.texture.get());
}

}  // namespace lumar::gl
