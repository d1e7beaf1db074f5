#include "shaders.h"

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
layout(location = 2) in vec3 light_attenuation;  // objects: what other objects take of the light
uniform mat4 model;
uniform mat3 normal_matrix;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
out vec3 attenuation;
// The objects' depth pre-pass and their shaded pass must agree to the bit (GL_LEQUAL).
invariant gl_Position;
void main() {
  vec4 w = model * vec4(position, 1.0);
  world_position = w.xyz;
  world_normal = normal_matrix * normal;
  attenuation = light_attenuation;
  gl_Position = view_projection * w;
}
)glsl";

const char* const kBackgroundFragment = R"glsl(
#version 450 core
layout(binding = 0) uniform sampler2D video;           // texel row 0 = top row of the frame
layout(binding = 1) uniform sampler2D undistortion_map; // RG32F, output size, row 0 = top
layout(binding = 4) uniform sampler2D response_decode;  // 256 x 1 RGB: linear value of each code
uniform bool use_undistortion_map;
uniform bool use_response_lut;  // false: the default sRGB response
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
  // Filter the encoded values, as cv::remap does, then decode. Alpha 0 marks video
  // pixels: the encode pass vignettes only what was rendered.
  vec3 code = texture(video, uv).rgb;
  if (use_response_lut) {
    // Linear interpolation between the table's entries at code * 255.
    vec3 x = (code * 255.0 + 0.5) / 256.0;
    color = vec4(texture(response_decode, vec2(x.r, 0.5)).r, texture(response_decode, vec2(x.g, 0.5)).g,
                 texture(response_decode, vec2(x.b, 0.5)).b, 0.0);
  } else {
    color = vec4(srgb_to_linear(code), 0.0);
  }
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
in vec3 attenuation;
uniform vec3 albedo;
uniform float exposure;
uniform vec3 sh[9];  // L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22 (world frame)
uniform bool use_volume;  // irradiance volume (gl/irradiance_textures.cpp) instead of sh
vec3 volume_irradiance(vec3 p, vec3 n);
vec3 sh9_irradiance(vec3 L0, vec3 L1, vec3 L2, vec3 L3, vec3 L4, vec3 L5, vec3 L6, vec3 L7, vec3 L8, vec3 n);
out vec4 color;

vec3 sh_irradiance(vec3 n) { return sh9_irradiance(sh[0], sh[1], sh[2], sh[3], sh[4], sh[5], sh[6], sh[7], sh[8], n); }

void main() {
  vec3 n = normalize(world_normal);
  // Nine coefficients can ring below zero opposite a bright source; light is never negative.
  vec3 irradiance = use_volume ? volume_irradiance(world_position, n) : max(sh_irradiance(n), vec3(0.0));
  irradiance *= clamp(attenuation, 0.0, 1.0);
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
layout(binding = 1) uniform sampler2D undistortion_map; // RG32F, output size, row 0 = top
layout(binding = 5) uniform sampler2D response_encode;  // N x 1 RGB: code / 255 at linear = s^2 * lut_max
uniform bool use_response_lut;
uniform bool use_undistortion_map;
uniform vec3 lut_max;            // linear value of code 255, per channel
uniform vec2 principal_point;    // OpenCV pixels of the video's (distorted) camera
uniform float half_diagonal;     // of the video's image, pixels
uniform vec2 vignetting;         // (a, b): gain 1 + a r^2 + b r^4
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
  vec4 v = texelFetch(linear_image, p, 0);
  // Rendered pixels (alpha 1) fall off towards the corners as the camera's own pixels
  // did; video pixels (alpha 0) already have the camera's vignetting.
  vec2 pixel = floor(gl_FragCoord.xy);  // the output's OpenCV pixel (its rows are flipped on read-back)
  // Vignetting belongs to the camera's own pixels: where this one came from in the video.
  if (use_undistortion_map) pixel = texelFetch(undistortion_map, ivec2(pixel), 0).xy;
  float r2 = dot(pixel - principal_point, pixel - principal_point) / (half_diagonal * half_diagonal);
  vec3 linear = v.rgb * mix(1.0, 1.0 + vignetting.x * r2 + vignetting.y * r2 * r2, v.a);
  if (use_response_lut) {
    vec3 s = sqrt(clamp(linear / lut_max, 0.0, 1.0));
    float n = float(textureSize(response_encode, 0).x);
    vec3 x = (s * (n - 1.0) + 0.5) / n;
    color = vec4(texture(response_encode, vec2(x.r, 0.5)).r, texture(response_encode, vec2(x.g, 0.5)).g,
                 texture(response_encode, vec2(x.b, 0.5)).b, 1.0);
  } else {
    color = vec4(linear_to_srgb(linear), 1.0);
  }
}
)glsl";

}  // namespace lumar::gl::shaders
