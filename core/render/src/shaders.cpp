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

const char* const kCameraResponseGlsl = R"glsl(
// The camera's response, from its code to linear light and back: one pair of tables for
// every pass that decodes or encodes codes (the video, the encode and resample passes).
layout(binding = 4) uniform sampler2D response_decode;  // 256 x 1 RGB: linear value of each code
uniform bool use_response_lut;  // false: the default sRGB response

vec3 srgb_to_linear(vec3 v) {
  return mix(v / 12.92, pow((v + 0.055) / 1.055, vec3(2.4)), greaterThan(v, vec3(0.04045)));
}

// The linear value of code / 255: linear interpolation between the table's entries.
vec3 decoded(vec3 code) {
  if (!use_response_lut) return srgb_to_linear(code);
  vec3 x = (clamp(code, 0.0, 1.0) * 255.0 + 0.5) / 256.0;
  return vec3(texture(response_decode, vec2(x.r, 0.5)).r, texture(response_decode, vec2(x.g, 0.5)).g,
              texture(response_decode, vec2(x.b, 0.5)).b);
}

layout(binding = 5) uniform sampler2D response_encode;  // N x 1 RGB: code / 255 at linear = s^2 * lut_max
uniform vec3 lut_max;  // linear value of code 255, per channel

vec3 linear_to_srgb(vec3 v) {
  v = clamp(v, 0.0, 1.0);
  return mix(v * 12.92, 1.055 * pow(v, vec3(1.0 / 2.4)) - 0.055, greaterThan(v, vec3(0.0031308)));
}

// Linear light to the camera's code over 255, through its response (back: decoded()).
vec3 encoded(vec3 linear) {
  if (!use_response_lut) return linear_to_srgb(linear);
  vec3 s = sqrt(clamp(linear / lut_max, 0.0, 1.0));
  float n = float(textureSize(response_encode, 0).x);
  vec3 x = (s * (n - 1.0) + 0.5) / n;
  return vec3(texture(response_encode, vec2(x.r, 0.5)).r, texture(response_encode, vec2(x.g, 0.5)).g,
              texture(response_encode, vec2(x.b, 0.5)).b);
}
)glsl";

const char* const kMeshVertex = R"glsl(
#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 light_attenuation;  // objects: what other objects take of the light
layout(location = 3) in vec4 occlusion;          // objects: bent normal (model space), open share
layout(location = 4) in vec3 bounce_light;       // objects: irradiance the other objects reflect onto it
layout(location = 5) in vec3 vertex_irradiance;  // objects shaded per vertex: E(bent normal) x open share
layout(location = 6) in float light_blocked;     // objects: the share of the exact lights they block themselves
uniform mat4 model;
uniform mat3 normal_matrix;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
out vec3 attenuation;
out vec4 self_occlusion;
out vec3 bounce;
out vec3 lit;
out float lights_blocked;
// The objects' depth pre-pass and their shaded pass must agree to the bit (GL_LEQUAL).
invariant gl_Position;
void main() {
  vec4 w = model * vec4(position, 1.0);
  world_position = w.xyz;
  world_normal = normal_matrix * normal;
  attenuation = light_attenuation;
  self_occlusion = vec4(normal_matrix * occlusion.xyz, occlusion.w);
  bounce = bounce_light;
  lit = vertex_irradiance;
  lights_blocked = light_blocked;
  gl_Position = view_projection * w;
}
)glsl";

const char* const kBackgroundFragment = R"glsl(
#version 450 core
layout(binding = 0) uniform sampler2D video;           // codes; texel row 0 = top row of the frame
layout(binding = 1) uniform sampler2D undistortion_map; // RG32F, output size, row 0 = top
uniform bool use_undistortion_map;
uniform vec2 output_size;
out vec4 color;

// One video pixel's linear light. Outside the frame: black when undistorting (as
// cv::remap's constant border), the nearest edge pixel when merely scaling.
vec3 video_pixel(ivec2 t) {
  ivec2 size = textureSize(video, 0);
  if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, size))) {
    if (use_undistortion_map) return decoded(vec3(0.0));
    t = clamp(t, ivec2(0), size - 1);
  }
  return decoded(texelFetch(video, t, 0).rgb);
}

void main() {
  // The OpenCV pixel of the video this fragment shows (the framebuffer's row 0 is the
  // bottom; OpenCV puts pixel centres at integers, GL at half-integers).
  vec2 here = vec2(gl_FragCoord.x, output_size.y - gl_FragCoord.y);
  vec2 p = use_undistortion_map ? texelFetch(undistortion_map, ivec2(here), 0).xy
                                : here / output_size * vec2(textureSize(video, 0)) - 0.5;
  // Bilinear in linear light (docs/conventions.md): neighbouring pixels' light mixes, their
  // codes do not. Mixing codes would darken every edge between a bright and a dark area.
  ivec2 t = ivec2(floor(p));
  vec2 w = p - floor(p);
  vec3 top = mix(video_pixel(t), video_pixel(t + ivec2(1, 0)), w.x);
  vec3 bottom = mix(video_pixel(t + ivec2(0, 1)), video_pixel(t + ivec2(1, 1)), w.x);
  // Alpha 0 marks video pixels: the encode pass vignettes only what was rendered.
  color = vec4(mix(top, bottom, w.y), 0.0);
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
in vec4 self_occlusion;  // bent normal (world; zero when not baked), open share
in vec3 bounce;          // irradiance the other objects reflect onto this point
in vec3 lit;             // the object's light per vertex (lighting/vertex_irradiance.h)
in float lights_blocked; // the share of the exact lights the object blocks itself (lighting/light_self_shadow.h)
uniform vec3 albedo;
uniform float exposure;
uniform vec3 sh[9];  // L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22 (world frame)
uniform bool use_volume;  // irradiance volume (gl/irradiance_textures.cpp) instead of sh
uniform bool use_self_occlusion;
uniform bool use_vertex_irradiance;  // `lit` already holds the volume's light and the self-occlusion
out vec4 color;

vec3 sh_irradiance(vec3 n) { return sh9_irradiance(sh[0], sh[1], sh[2], sh[3], sh[4], sh[5], sh[6], sh[7], sh[8], n); }

void main() {
  vec3 irradiance = lit;
  if (!use_vertex_irradiance) {
    vec3 n = normalize(world_normal), bent = n;
    // The object's own occlusion: the room's light of the open directions, E(bent normal),
    // times the open share (lighting/self_occlusion.h); the exact lights at the normal,
    // less what the object blocks of them (lighting/light_self_shadow.h).
    float open = 1.0, lights = 1.0;
    if (use_self_occlusion) {
      if (dot(self_occlusion.xyz, self_occlusion.xyz) > 1e-12) {
        bent = normalize(self_occlusion.xyz);
        open = clamp(self_occlusion.w, 0.0, 1.0);
      }
      lights = 1.0 - clamp(lights_blocked, 0.0, 1.0);
    }
    // Nine coefficients can ring below zero opposite a bright source; light is never negative.
    irradiance = use_volume ? volume_irradiance(world_position, bent, n, open, lights)
                            : open * max(sh_irradiance(bent), vec3(0.0));
  }
  irradiance *= clamp(attenuation, 0.0, 1.0);
  irradiance += max(bounce, vec3(0.0));
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
uniform bool map_coordinates;  // write the map's (u, v) in [0, 1) instead of its radiance
out vec4 color;
void main() {
  // Lat-long convention (latlong.h): d = (sin t cos p, cos t, sin t sin p), u = p / 2pi, v = t / pi.
  vec3 d = normalize(map_from_world * (world_position - capture_position));
  float phi = atan(d.z, d.x);
  if (phi < 0.0) phi += 6.28318530717959;
  float theta = acos(clamp(d.y, -1.0, 1.0));
  vec2 uv = vec2(phi / 6.28318530717959, theta / 3.14159265358979);
  color = map_coordinates ? vec4(uv, 0.0, 1.0) : vec4(texture(environment, uv).rgb, 1.0);
}
)glsl";

const char* const kEncodeFragment = R"glsl(
#version 450 core
layout(binding = 3) uniform sampler2D linear_image;
layout(binding = 1) uniform sampler2D undistortion_map; // RG32F, output size, row 0 = top
uniform bool use_undistortion_map;
uniform vec2 principal_point;    // OpenCV pixels of the video's (distorted) camera
uniform float half_diagonal;     // of the video's image, pixels
uniform vec2 vignetting;         // (a, b): gain 1 + a r^2 + b r^4
uniform bool use_noise;
uniform vec3 noise_read_variance, noise_shot_gain;  // the sensor's: variance = read + gain * linear
uniform uint noise_seed;         // a new one every frame
// The codec's chroma subsampling, within chroma_region (linear_image's texels, rows bottom
// up, x0 y0 x1 y1, the ends excluded), where rendered pixels lie: pixels per chroma sample,
// 1 or 2 each way.
uniform ivec2 chroma_block;
uniform ivec4 chroma_region;
out vec4 color;

// A 32-bit integer hash (Wellons' "lowbias32"): the noise's random numbers, per pixel and frame.
uint noise_hash(uint x) {
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
  return x;
}
float noise_uniform(uint h) { return (float(h >> 8) + 0.5) / 16777216.0; }
// Three independent standard normal numbers (Box-Muller).
vec3 noise_gaussian(ivec2 pixel) {
  uint h = noise_hash(uint(pixel.x) + noise_hash(uint(pixel.y) + noise_hash(noise_seed)));
  float u1 = noise_uniform(h), u2 = noise_uniform(noise_hash(h ^ 0x9e3779b9u));
  float u3 = noise_uniform(noise_hash(h ^ 0x85ebca6bu)), u4 = noise_uniform(noise_hash(h ^ 0xc2b2ae35u));
  float r1 = sqrt(-2.0 * log(u1)), r2 = sqrt(-2.0 * log(u3));
  const float tau = 6.28318530717959;
  return vec3(r1 * cos(tau * u2), r1 * sin(tau * u2), r2 * cos(tau * u4));
}

// The linear light at OpenCV pixel q (clamped to the image), in alpha its rendered share.
// Rendered pixels (alpha 1) fall off towards the corners as the camera's own pixels did;
// video pixels (alpha 0) already have the camera's vignetting.
vec4 exposed(ivec2 q) {
  ivec2 size = textureSize(linear_image, 0);
  q = clamp(q, ivec2(0), size - 1);
  vec4 v = texelFetch(linear_image, ivec2(q.x, size.y - 1 - q.y), 0);  // the image's rows are upside down
  // Vignetting belongs to the camera's own pixels: where this one came from in the video.
  vec2 pixel = vec2(q);
  if (use_undistortion_map) pixel = texelFetch(undistortion_map, q, 0).xy;
  float r2 = dot(pixel - principal_point, pixel - principal_point) / (half_diagonal * half_diagonal);
  return vec4(v.rgb * mix(1.0, 1.0 + vignetting.x * r2 + vignetting.y * r2 * r2, v.a), v.a);
}

// The weights of the pixels a decoder's chroma at coordinate c mixes, along one axis, from
// `first` on: each chroma sample the mean of its `block` pixels, then interpolated between
// the samples' centres as libjpeg's "fancy" upsampling does (3/4 the own, 1/4 the nearer
// neighbour's).
void chroma_taps(int c, int block, out int first, out vec4 w) {
  if (block == 1) {
    first = c, w = vec4(1.0, 0.0, 0.0, 0.0);
  } else if ((c & 1) == 0) {
    first = c - 2, w = vec4(1.0, 1.0, 3.0, 3.0) / 8.0;
  } else {
    first = c - 1, w = vec4(3.0, 3.0, 1.0, 1.0) / 8.0;
  }
}

void main() {
  ivec2 size = textureSize(linear_image, 0);
  // Written upside down so that glReadPixels returns the top row first: the output's
  // OpenCV pixel is the fragment's.
  ivec2 q = ivec2(gl_FragCoord.xy);
  vec4 v = exposed(q);
  vec3 linear = v.rgb;
  ivec2 texel = ivec2(q.x, size.y - 1 - q.y);
  if (chroma_block != ivec2(1) && all(greaterThanEqual(texel, chroma_region.xy)) &&
      all(lessThan(texel, chroma_region.zw))) {
    // The camera's codec keeps each pixel's luma and the chroma of its neighbourhood: a
    // rendered pixel's colour bleeds into the video around it, and the video's into it.
    ivec2 first;
    vec4 wx, wy;
    chroma_taps(q.x, chroma_block.x, first.x, wx);
    chroma_taps(q.y, chroma_block.y, first.y, wy);
    // Only where a rendered pixel is among those mixed (most of the region is video).
    float rendered = 0.0;
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        ivec2 t = clamp(first + ivec2(i, j), ivec2(0), size - 1);
        if (wx[i] * wy[j] > 0.0) rendered += texelFetch(linear_image, ivec2(t.x, size.y - 1 - t.y), 0).a;
      }
    if (rendered > 0.0) {
      vec3 mixed = vec3(0.0);
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          float w = wx[i] * wy[j];
          if (w > 0.0) mixed += w * encoded(exposed(first + ivec2(i, j)).rgb);
        }
      // The mixed colour's chroma with this pixel's luma: a grey added changes luma only.
      const vec3 luma = vec3(0.299, 0.587, 0.114);  // JFIF's, of R, G, B
      vec3 own = encoded(linear);
      linear = decoded(clamp(mixed + dot(own - mixed, luma), 0.0, 1.0));
    }
  }
  // The sensor's noise on what was rendered, in proportion to its share of the pixel (the
  // video's own pixels have theirs). After the codec: its level was measured on the
  // footage the codec had already smoothed.
  if (use_noise && v.a > 0.0)
    linear += v.a * noise_gaussian(texel) * sqrt(noise_read_variance + noise_shot_gain * max(linear, vec3(0.0)));
  color = vec4(encoded(linear), 1.0);
}
)glsl";

const char* const kBlurFragment = R"glsl(
#version 450 core
layout(binding = 3) uniform sampler2D linear_image;  // the unblurred image (alpha 1: rendered)
layout(binding = 6) uniform sampler2D source;        // this pass's input
uniform float sigma;  // pixels
uniform int radius;   // pixels: min(ceil(3 sigma), 12)
uniform ivec2 step;   // (1, 0): rows; (0, 1): columns, the last pass
out vec4 color;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), size = textureSize(source, 0);
  vec4 sum = vec4(0.0);
  float total = 0.0;
  for (int i = -radius; i <= radius; ++i) {
    float w = exp(-0.5 * float(i * i) / (sigma * sigma));
    sum += w * texelFetch(source, clamp(p + i * step, ivec2(0), size - 1), 0);
    total += w;
  }
  vec4 b = sum / total;
  // After the columns: the blur where it reaches a rendered pixel, the video as it was
  // elsewhere (the camera blurred it already).
  color = step.y == 1 && b.a <= 0.0 ? texelFetch(linear_image, p, 0) : b;
}
)glsl";

const char* const kResampleFragment = R"glsl(
#version 450 core
layout(binding = 3) uniform sampler2D linear_image;      // the scene, rows bottom up (alpha > 0: rendered)
layout(binding = 8) uniform sampler2D encoded_image;     // the encode pass's output: codes / 255, OpenCV rows
layout(binding = 1) uniform sampler2D undistortion_map;  // RG32F, output size, row 0 = top
out vec4 color;

// The truth's video is sampled, clipped and coded at the camera's pixels, then undistorted
// bilinearly: at a video pixel's fractional offset f the undistortion mixes
// (1 - f, f) of two neighbours, a blur of variance f(1 - f) after the clipping. The video
// here had it in the background pass; rendered pixels get it now, after their clipping,
// as a symmetric 3-tap (a, 1 - 2a, a) of the same variance, a = f(1 - f) / 2.
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), size = textureSize(encoded_image, 0);
  vec4 here = texelFetch(encoded_image, p, 0);
  vec2 f = fract(texelFetch(undistortion_map, p, 0).xy);
  vec2 a = 0.5 * f * (1.0 - f);
  vec3 wx = vec3(a.x, 1.0 - 2.0 * a.x, a.x), wy = vec3(a.y, 1.0 - 2.0 * a.y, a.y);
  bool rendered_here = texelFetch(linear_image, ivec2(p.x, size.y - 1 - p.y), 0).a > 0.0;
  // A video pixel takes only its rendered neighbours' share: its own resampling is done.
  vec3 sum = vec3(0.0);
  float taken = 0.0;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      ivec2 n = clamp(p + ivec2(i - 1, j - 1), ivec2(0), size - 1);
      if (!rendered_here && texelFetch(linear_image, ivec2(n.x, size.y - 1 - n.y), 0).a <= 0.0) continue;
      float w = wx[i] * wy[j];
      sum += w * decoded(texelFetch(encoded_image, n, 0).rgb);
      taken += w;
    }
  if (taken <= 0.0) {
    color = here;
    return;
  }
  color = vec4(encoded(sum + (1.0 - taken) * decoded(here.rgb)), 1.0);
}
)glsl";

const char* const kCoveredFragment = R"glsl(
#version 450 core
out vec4 color;
void main() { color = vec4(1.0); }
)glsl";

const char* const kAntialiasFragment = R"glsl(
#version 450 core
layout(binding = 3) uniform sampler2D linear_image;  // one sample per pixel; alpha 1: object
layout(binding = 7) uniform sampler2D coverage;      // the objects' share of each pixel
out vec4 color;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), size = textureSize(linear_image, 0);
  vec4 here = texelFetch(linear_image, p, 0);
  float c = texelFetch(coverage, p, 0).r;
  bool object_here = here.a > 0.5;
  if ((object_here && c >= 1.0) || (!object_here && c <= 0.0)) {
    color = here;
    return;
  }
  // The pixel's centre shows one kind; the other kind's colour is its neighbours'.
  vec3 object = vec3(0.0), video = vec3(0.0);
  float objects = 0.0, videos = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      vec4 q = texelFetch(linear_image, clamp(p + ivec2(dx, dy), ivec2(0), size - 1), 0);
      if (q.a > 0.5) {
        object += q.rgb;
        objects += 1.0;
      } else {
        video += q.rgb;
        videos += 1.0;
      }
    }
  vec3 o = object_here ? here.rgb : object / max(objects, 1.0);
  vec3 v = object_here ? (videos > 0.0 ? video / videos : here.rgb) : here.rgb;
  if (!object_here && objects == 0.0) o = here.rgb;
  color = vec4(mix(v, o, c), c);
}
)glsl";

const char* const kWeightedCopyFragment = R"glsl(
#version 450 core
layout(binding = 3) uniform sampler2D linear_image;
uniform float weight;
out vec4 color;
void main() { color = weight * texelFetch(linear_image, ivec2(gl_FragCoord.xy), 0); }
)glsl";

}  // namespace lumar::gl::shaders
