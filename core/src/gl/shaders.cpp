#include "gl/shaders.h"

namespace lumar::gl::shaders {

const char* const kFullscreenVertex = R"glsl(
#version 450 core
void main() {
  // Vertices (-1,-1), (3,-1), (-1,3): one triangle that covers the whole viewport.
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)glsl";

const char* const kMeshVertex = R"glsl(
#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 model;
uniform mat3 normal_matrix;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
void main() {
  vec4 w = model * vec4(position, 1.0);
  world_position = w.xyz;
  world_normal = normal_matrix * normal;
  gl_Position = view_projection * w;
}
)glsl";

const char* const kBackgroundFragment = R"glsl(
#version 450 core
layout(binding = 0) uniform sampler2D video;           // texel row 0 = top row of the frame
layout(binding = 1) uniform sampler2D undistortion_map; // RG32F, output size, row 0 = top
uniform bool use_undistortion_map;
uniform vec2 output_size;
out vec4 color;

vec3 srgb_to_linear(vec3 v) {
  return mix(v / 12.92, pow((v + 0.055) / 1.055, vec3(2.4)), greaterThan(v, vec3(0.04045)));
}

void main() {
  vec2 uv;
  if (use_undistortion_map) {
    // OpenCV pixel of this fragment (the framebuffer's row 0 is the bottom).
    ivec2 pixel = ivec2(gl_FragCoord.x, output_size.y - gl_FragCoord.y);
    // OpenCV puts pixel centres at integers, GL at half-integers.
    uv = (texelFetch(undistortion_map, pixel, 0).xy + 0.5) / vec2(textureSize(video, 0));
  } else {
    uv = vec2(gl_FragCoord.x, output_size.y - gl_FragCoord.y) / output_size;
  }
  // Filter the encoded values, as cv::remap does, then decode.
  color = vec4(srgb_to_linear(texture(video, uv).rgb), 1.0);
}
)glsl";

const char* const kDepthOnlyFragment = R"glsl(
#version 450 core
void main() {}
)glsl";

const char* const kShadedObjectFragment = R"glsl(
#version 450 core
in vec3 world_position;
in vec3 world_normal;
uniform vec3 albedo;
uniform float exposure;
uniform vec3 sh[9];  // L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22 (world frame)
out vec4 color;

// Ramamoorthi & Hanrahan 2001, eq. 13, with the world normal's x, y, z.
vec3 sh_irradiance(vec3 n) {
  const float c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708;
  float x = n.x, y = n.y, z = n.z;
  return c1 * sh[8] * (x * x - y * y) + c3 * sh[6] * z * z + c4 * sh[0] - c5 * sh[6] +
         2.0 * c1 * (sh[4] * x * y + sh[7] * x * z + sh[5] * y * z) +
         2.0 * c2 * (sh[3] * x + sh[1] * y + sh[2] * z);
}

void main() {
  vec3 n = normalize(world_normal);
  // Nine coefficients can ring below zero opposite a bright source; light is never negative.
  vec3 irradiance = max(sh_irradiance(n), vec3(0.0));
  color = vec4(albedo * irradiance * (exposure / 3.14159265358979), 1.0);
}
)glsl";

const char* const kWorldPositionFragment = R"glsl(
#version 450 core
in vec3 world_position;
in vec3 world_normal;
out vec4 color;
void main() { color = vec4(world_position, 1.0); }
)glsl";

const char* const kRoomRadianceFragment = R"glsl(
#version 450 core
in vec3 world_position;
in vec3 world_normal;
layout(binding = 2) uniform sampler2D environment;  // lat-long, RGB32F, repeat in u, clamp in v
uniform vec3 capture_position;
uniform mat3 map_from_world;   // Ry(-azimuth offset)
out vec4 color;
void main() {
  // Lat-long convention (latlong.h): d = (sin t cos p, cos t, sin t sin p), u = p / 2pi, v = t / pi.
  vec3 d = normalize(map_from_world * (world_position - capture_position));
  float phi = atan(d.z, d.x);
  if (phi < 0.0) phi += 6.28318530717959;
  float theta = acos(clamp(d.y, -1.0, 1.0));
  vec2 uv = vec2(phi / 6.28318530717959, theta / 3.14159265358979);
  color = vec4(texture(environment, uv).rgb, 1.0);
}
)glsl";

const char* const kEncodeFragment = R"glsl(
#version 450 core
layout(binding = 3) uniform sampler2D linear_image;
out vec4 color;

vec3 linear_to_srgb(vec3 v) {
  v = clamp(v, 0.0, 1.0);
  return mix(v * 12.92, 1.055 * pow(v, vec3(1.0 / 2.4)) - 0.055, greaterThan(v, vec3(0.0031308)));
}

void main() {
  // Written upside down so that glReadPixels returns the top row first.
  ivec2 size = textureSize(linear_image, 0);
  ivec2 p = ivec2(gl_FragCoord.xy);
  p.y = size.y - 1 - p.y;
  color = vec4(linear_to_srgb(texelFetch(linear_image, p, 0).rgb), 1.0);
}
)glsl";

}  // namespace lumar::gl::shaders
