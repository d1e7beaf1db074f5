#include "lumar/pipeline/quality_choice.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

#include "lumar/base/error.h"
#include "lumar/calib/undistortion.h"
#include "lumar/lighting/irradiance_volume.h"

namespace lumar::pipeline {

namespace {

// Full quality's composites and what the measure needs beside them, per probe frame.
struct Reference {
  std::vector<cv::Mat> composite, empty, mask;
};

QualityTrial run_trial(Overlay& overlay, const std::vector<ProbeFrame>& frames, const OverlayQuality& quality,
                       Reference& reference) {
  overlay.set_quality(quality);
  QualityTrial trial;
  trial.quality = quality;
  CompositeErrorMeter meter(overlay.response());
  const bool is_reference = reference.composite.empty();
  std::vector<double> ms;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const OverlayFrame out = overlay.composite(frames[i].frame, frames[i].T_world_camera, frames[i].shutter_cameras);
    if (i > 0) ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (is_reference) {
      reference.composite.push_back(out.composite);
      reference.empty.push_back(
          calib::undistort_in_linear_light(frames[i].frame.image, overlay.undistortion(), overlay.response()));
      reference.mask.push_back(overlay.compositor().renderer().render_object_mask(frames[i].T_world_camera));
    }
    meter.add(out.composite, reference.composite[i], reference.composite[i], reference.empty[i], reference.mask[i]);
  }
  std::nth_element(ms.begin(), ms.begin() + std::ptrdiff_t(ms.size() / 2), ms.end());
  trial.ms_per_frame = ms[ms.size() / 2];
  trial.difference = meter.result();
  return trial;
}

bool within(const CompositeError& e, double percent) {
  return e.object_err <= percent && e.edge_err <= percent && e.shadow_err <= percent;
}

}  // namespace

QualityChoice choose_quality(Overlay& overlay, const std::vector<ProbeFrame>& frames, const QualityBudget& budget) {
  if (frames.size() < 2)
    throw InputError("quality auto: needs at least two frames with a camera pose to measure the settings on");
  const gl::CompositeFeatures features = overlay.compositor().renderer().features();
  gl::CompositeFeatures quiet = features;
  quiet.noise = false;
  overlay.compositor().set_features(quiet);

  QualityChoice choice;
  choice.budget = budget;
  Reference reference;
  const auto log = [&](const QualityTrial& t) {
    spdlog::info(
        "quality auto: {:<48} {:6.1f} ms/frame; against full quality object {:.2f} %, edge {:.2f} %, shadow {:.2f} "
        "%{}",
        t.quality.describe(), t.ms_per_frame, t.difference.object_err, t.difference.edge_err, t.difference.shadow_err,
        &t == &choice.trials.front() ? " (the reference)"
        : t.kept                     ? ": kept"
                                     : "");
  };
  choice.trials.push_back(run_trial(overlay, frames, overlay.quality(), reference));
  choice.trials.back().kept = true;
  log(choice.trials.back());

  // Each knob's levels, cheapest last; a level is tried from the best setting so far.
  const auto step = [&](auto&& with_level, const auto& levels) {
    for (const auto& level : levels) {
      OverlayQuality q = choice.choice().quality;
      if (!with_level(q, level)) continue;  // already there, or cheaper
      QualityTrial t = run_trial(overlay, frames, q, reference);
      const bool inside = within(t.difference, budget.percent);
      t.kept = inside && t.ms_per_frame < (1.0 - kQualityMinGain) * choice.choice().ms_per_frame;
      choice.trials.push_back(t);
      log(choice.trials.back());
      if (t.kept) choice.chosen = choice.trials.size() - 1;
      if (!inside) break;  // the knob's next level is coarser still
    }
  };
  step(
      [](OverlayQuality& q, ObjectShading s) {
        if (q.shading == s) return false;
        q.shading = s;
        return true;
      },
      std::vector<ObjectShading>{ObjectShading::PerVertex});
  const int lines = choice.full().quality.shadows.lines_per_patch;
  step(
      [](OverlayQuality& q, int n) {
        if (n < 1 || n >= q.shadows.lines_per_patch) return false;
        q.shadows.lines_per_patch = n;
        return true;
      },
      std::vector<int>{lines / 2, lines / 4});
  // Full quality's volume: its exact lights, and their shadow maps' size.
  const IrradianceVolume* volume = overlay.compositor().irradiance_volume().get();
  const int lights = volume ? int(volume->lights.size()) : 0, map_n = volume ? volume->shadow_n : 0;
  step(
      [&](OverlayQuality& q, int n) {
        if (n >= q.exact_lights.value_or(lights)) return false;
        q.exact_lights = n;
        return true;
      },
      std::vector<int>{6, 2});
  step(
      [&](OverlayQuality& q, int n) {
        if (q.exact_lights.value_or(lights) == 0 || n >= q.shadow_map.value_or(map_n)) return false;
        q.shadow_map = n;
        return true;
      },
      std::vector<int>{64, 32});
  step(
      [](OverlayQuality& q, double px) {
        if (px <= q.coverage_mesh_px) return false;
        q.coverage_mesh_px = px;
        return true;
      },
      std::vector<double>{0.5, 1.0, 2.0, 4.0});

  overlay.set_quality(choice.choice().quality);
  overlay.compositor().set_features(features);
  overlay.reset_times();
  spdlog::info("quality auto: {} on {} frames", choice.describe(), frames.size());
  return choice;
}

std::string QualityChoice::describe() const {
  const QualityTrial& c = choice();
  return fmt::format(
      "{}: {:.1f} ms/frame against full quality's {:.1f} ({:.2f}x), within {:.2f} % of it (object {:.2f} %, edge "
      "{:.2f} %, shadow {:.2f} %), from {} trials",
      c.quality.describe(), c.ms_per_frame, full().ms_per_frame, c.ms_per_frame / full().ms_per_frame, budget.percent,
      c.difference.object_err, c.difference.edge_err, c.difference.shadow_err, trials.size());
}

}  // namespace lumar::pipeline
