#pragma once
// Radiosity lines (precomputed once per scene): for every receiver point and every
// emitter sample point, the unoccluded transfer (irradiance the point receives from the
// sample, with visibility against the proxy room), as a fraction of the point's whole
// unshadowed irradiance, per RGB channel. A virtual object that blocks a line removes
// that fraction: attenuation = E_with / E_without = 1 - sum of blocked fractions.
//
// Lines are grouped for culling: by emitter sample point (a pencil of lines meeting at
// it), then by receiver in the order of the receiver grids (shadow_receiver_grid.h), so a
// run of receivers in one grid row is a run of lines. Lines below a significance are
// dropped, but their energy stays in E_without, so the ratio stays exact up to the
// dropped share (at most ShadowLineOptions::max_dropped_fraction per receiver).
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "lumar/lighting/ray_scene.h"
#include "lumar/lighting/shadows/shadow_emitters.h"
#include "lumar/lighting/shadows/shadow_receiver_grid.h"

namespace lumar {

struct ShadowLine {
  std::uint32_t receiver = 0;  // index into ShadowLines::origins
  std::uint32_t sample = 0;    // index into ShadowLines::samples
  glm::vec3 fraction{0.0f};    // share of the receiver's E_without carried, per channel
};

struct ShadowLineOptions {
  // Largest share of a receiver's irradiance that may be dropped as insignificant lines
  // (the smallest lines go first); bounds the error this adds to the attenuation.
  double max_dropped_fraction = 0.002;
};

struct ShadowLines {
  bool distant = false;
  std::vector<glm::vec3> origins;     // shadow ray origins (receiver points nudged along their normal)
  std::vector<EmitterPoint> samples;  // line ends (emitter sample points)
  std::uint32_t patch_count = 0;
  ReceiverGrids grids;                      // over the origins
  std::vector<ShadowLine> lines;            // by sample, then by receiver in grids.order
  std::vector<std::uint32_t> sample_first;  // sample s: lines[sample_first[s], sample_first[s+1])
  std::vector<glm::vec3> unshadowed;        // E_without per receiver (with proxy visibility), RGB
  std::vector<float> dropped;               // share of E_without dropped per receiver (luminance-weighted max channel)
  std::size_t candidate_lines = 0;          // lines with non-zero transfer before dropping

  std::size_t receiver_count() const { return origins.size(); }
  // End point of a line (distant: kDistantLineLength away along the sample's direction).
  glm::vec3 line_end(const ShadowLine& l) const {
    return emitter_line_end(samples[l.sample], distant, origins[l.receiver]);
  }
};

// Precompute (parallel with TBB). `positions`, `normals`: receiver points and unit
// normals; `proxy`: the room (may be empty).
ShadowLines build_shadow_lines(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                               const Emitters& emitters, const RayScene& proxy, const ShadowLineOptions& options = {});

// Far end of a shadow ray towards `end`, as a fraction of (end - origin): stops just
// short of the emitting proxy surface; runs to the end for a distant light.
inline float shadow_ray_t_far(bool distant) { return distant ? 1.0f : 0.999f; }

}  // namespace lumar
