#pragma once
// Video is display-encoded; compositing happens in linear light. Until a camera's
// response is calibrated, the documented default response is the sRGB transfer
// curve with a linear gain ("exposure": video linear value per unit of scene radiance).
#include <cmath>
#include <glm/glm.hpp>

namespace lumar {

inline float srgb_to_linear(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }
inline float linear_to_srgb(float v) {
  v = v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
  return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

// Luminance of linear RGB (Rec. 709 primaries).
inline double luminance(const glm::dvec3& c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

// The largest of the three channels.
inline float max_channel(const glm::vec3& c) { return c.r > c.g ? (c.r > c.b ? c.r : c.b) : (c.g > c.b ? c.g : c.b); }

}  // namespace lumar
