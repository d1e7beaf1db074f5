#include "lumar/pipeline/lighting_followed.h"

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/scene/mesh.h"

namespace lumar::pipeline {

namespace {

struct Samples {  // world positions and normals of some of an object's vertices
  std::vector<glm::dvec3> positions, normals;
};
Samples object_samples(const LoadedObject& o) {
  Samples s;
  const Mesh posed = transformed(o.model, o.T_world_model);
  for (std::size_t i = 0; i < posed.positions.size(); i += 13) {
    s.positions.emplace_back(posed.positions[i]);
    s.normals.emplace_back(posed.normals[i]);
  }
  return s;
}
std::vector<glm::dvec3> irradiance(const IrradianceVolume& v, const Samples& s) {
  std::vector<glm::dvec3> e;
  for (std::size_t i = 0; i < s.positions.size(); ++i) e.push_back(v.evaluate(s.positions[i], s.normals[i]));
  return e;
}
double relative_error(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b) {
  double num = 0, den = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) num += std::abs(a[i][c] - b[i][c]), den += b[i][c];
  return num / den;
}
double brightness(const std::vector<glm::dvec3>& e) {
  double sum = 0;
  for (const auto& x : e) sum += luminance(x);
  return sum / double(e.size());
}

// The first object's shadow on the floor as lines built from `scene`'s map give it.
std::vector<glm::vec3> shadow_of(const LoadedScene& scene) {
  const ShadowScene shadows(scene);
  const Mesh receivers = shadows.receivers();
  const Emitters emitters = shadows.emitters(receivers.positions, receivers.normals, EmitterOptions{});
  LineShadows lines(build_shadow_lines(receivers.positions, receivers.normals, emitters, shadows.proxy()));
  lines.add_object(scene.objects.front().model, scene.objects.front().T_world_model);
  lines.update();
  return lines.attenuation();
}
double shadow_error(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  double num = 0, den = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) num += std::abs(a[i][c] - b[i][c]), den += 1.0 - b[i][c];
  return den > 0 ? num / den : 0.0;
}

}  // namespace

LightingFollowed follow_lighting_change(const std::filesystem::path& recording, const EnvironmentMap& changed_map,
                                        double change_at_s, const ReplayOverlaySettings& settings, double tolerance) {
  if (settings.overlay.adapt_lighting_every <= 0)
    throw InputError("follow_lighting_change: the overlay must adapt its lighting (adapt_lighting_every > 0)");
  ReplayOverlay replay(recording, settings);
  const LoadedScene& scene = replay.scene();
  if (scene.objects.empty() || !replay.compositor().irradiance_volume())
    throw InputError(recording.string() + ": the scene needs an object lit by an irradiance volume");
  const Samples samples = object_samples(scene.objects.front());
  const auto captured = irradiance(*replay.compositor().irradiance_volume(), samples);
  LoadedScene changed = scene;
  changed.map = changed_map;
  const auto truth = irradiance(scene_irradiance_volume(changed, scene.manifest.lighting.method, false), samples);

  LightingFollowed f;
  f.baseline_err = relative_error(captured, truth);
  double previous = brightness(captured);
  std::vector<std::pair<double, double>> errors;  // (time, error against the truth) after the change
  replay.run(0, [&](const OverlayFrame& frame) {
    const auto e = irradiance(*replay.compositor().irradiance_volume(), samples);
    const double t = nanos_to_seconds(frame.time);
    f.worst_step = std::max(f.worst_step, std::abs(brightness(e) / previous - 1.0));
    previous = brightness(e);
    if (t < change_at_s)
      f.before_err = std::max(f.before_err, relative_error(e, captured));
    else
      errors.emplace_back(t, relative_error(e, truth));
    return true;
  });
  if (errors.empty()) throw InputError(recording.string() + ": the recording ends before the change");
  f.end_err = errors.back().second;
  for (std::size_t k = errors.size(); k-- > 0;)
    if (errors[k].second > tolerance) {
      if (k + 1 < errors.size()) f.settled_after_s = errors[k + 1].first - change_at_s;
      break;
    } else if (k == 0) {
      f.settled_after_s = errors[0].first - change_at_s;
    }
  const LiveLighting& lighting = *replay.live_lighting();
  f.bakes = lighting.bakes();
  f.worst_fade_step_ms = lighting.worst_fade_step_ms();
  f.adaptation_ms_per_frame = replay.times().lighting / std::max(1, replay.times().frames);
  if (const LineShadows* lines = replay.compositor().shadows()) {
    const auto shadow_truth = shadow_of(changed);
    f.shadow_err = shadow_error(lines->attenuation(), shadow_truth);
    f.shadow_baseline_err = shadow_error(shadow_of(scene), shadow_truth);
  }
  return f;
}

}  // namespace lumar::pipeline
