#pragma once
// How well the overlay follows a change of the room's light (docs/envmap.md, "Keeping the
// map current"): replays a recording with the lighting adaptation on and measures, every
// frame, the first object's irradiance on every 13th vertex from the compositor's volume
// against the volume built from the changed map (the truth) and from the captured map
// (what the object would keep without adapting); at the end, its shadow on the floor
// against lines built from the changed map. Shared by the tests and bench_lighting_change.
#include <filesystem>

#include "lumar/pipeline/replay_overlay.h"
#include "lumar/scene/envmap.h"

namespace lumar::pipeline {

struct LightingFollowed {
  double baseline_err = 0;      // the captured map's volume against the truth
  double before_err = 0;        // the adapted lighting against the captured map's, before the change (worst)
  double end_err = 0;           // the adapted lighting against the truth, last frame
  double settled_after_s = -1;  // from the change until the error stays within `tolerance`; -1: never
  double worst_step = 0;        // largest frame-to-frame change of the object's brightness (relative)
  int bakes = 0;
  double worst_fade_step_ms = 0;       // LiveLighting::worst_fade_step_ms
  double adaptation_ms_per_frame = 0;  // the "lighting adaptation" stage, bakes included
  // The object's shadow on the floor at the end against lines built from the changed map
  // (Σ|a − b| / Σ(1 − b)): as relit, and as the captured map's lines leave it.
  double shadow_err = 0, shadow_baseline_err = 0;
};

// Errors are Σ|a − b| / Σ b over the sampled vertices and the three channels. `settings`
// must adapt the lighting (overlay.adapt_lighting_every > 0); InputError otherwise.
LightingFollowed follow_lighting_change(const std::filesystem::path& recording, const EnvironmentMap& changed_map,
                                        double change_at_s, const ReplayOverlaySettings& settings,
                                        double tolerance = 0.05);

}  // namespace lumar::pipeline
