// The overlay follows the room's light as it changes (issue: "lighting follows the
// room"): two synthetic recordings, a lamp on the ceiling going out and the window's light
// turning warmer, replayed with --adapt-lighting. The objects' irradiance is measured on
// the figurine's vertices from the compositor's volume, every frame, against the volume
// built from the changed map (the truth) and the one built from the captured map (what
// the objects would keep without adapting).
#include <gtest/gtest.h>

#include <cstdio>

#include "lumar/base/color.h"
#include "lumar/calib/camera_file.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/pipeline/replay_overlay.h"
#include "lumar/sim/light_change.h"
#include "lumar/sim/synthetic_recording.h"
#include "test_paths.h"

namespace lumar {
namespace {

constexpr gl::CompositeFeatures kNoFeatures{false, false, false, false, false};
constexpr double kFps = 24.0;
// A third of the automatic exposure (18 % grey), so that the window does not clip: a
// clipped window's colour cannot be measured (docs/envmap.md).
constexpr double kWindowExposure = 0.065;

std::filesystem::path scene_file() { return test::source_dir() / "data/scenes/room/scene.json"; }

// The camera stands back and turns from the figurine up to the ceiling lamp and the
// window (sim "room" path); the change happens when the lamp is in view.
std::filesystem::path record(const std::filesystem::path& out, const sim::LightChange& change, int frames,
                             double exposure = 0.0) {
  sim::SynthSettings s;
  s.scene = scene_file();
  s.out = out;
  s.camera = calib::load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  s.frames = frames;
  s.fps = kFps;
  s.supersample = 1;
  s.path = "room";
  s.exposure = exposure;
  s.light_change = change;
  sim::synthesize_recording(s);
  return out;
}

sim::LightChange lamp_off() {
  sim::LightChange c;  // the ceiling lamp at (-1.2, 3, 0.3): 13 % of the map's power
  c.region = {{-1.45, 2.9, 0.15}, {-0.95, 3.1, 0.45}};
  c.brighter_than = 5.0;
  c.scale = glm::dvec3(0.0);
  c.at_s = 2.5;
  return c;
}

sim::LightChange warmer_window() {
  sim::LightChange c;  // the window on the far wall: 16 % of the map's power, bluish daylight
  c.region = {{-3.1, 0.3, -2.5}, {-2.9, 2.75, -0.2}};
  c.scale = glm::dvec3(1.5, 1.0, 0.5);
  c.at_s = 1.5;
  c.ramp_s = 0.5;
  return c;
}

// Irradiance on a sample of the object's vertices (world positions and normals).
struct Samples {
  std::vector<glm::dvec3> positions, normals;
};
Samples object_samples(const LoadedObject& o) {
  Samples s;
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(o.T_world_model)));
  for (std::size_t i = 0; i < o.model.positions.size(); i += 13) {
    s.positions.push_back(glm::dvec3(o.T_world_model * glm::dvec4(glm::dvec3(o.model.positions[i]), 1.0)));
    s.normals.push_back(glm::normalize(normal_matrix * glm::dvec3(o.model.normals[i])));
  }
  return s;
}
std::vector<glm::dvec3> irradiance(const IrradianceVolume& v, const Samples& s) {
  std::vector<glm::dvec3> e;
  for (std::size_t i = 0; i < s.positions.size(); ++i) e.push_back(v.evaluate(s.positions[i], s.normals[i]));
  return e;
}
// Σ |a - b| / Σ b over vertices and channels.
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

struct Followed {
  double baseline_err = 0;      // the captured map's volume against the truth after the change
  double before_err = 0;        // the adapted lighting against the captured map's, before the change
  double end_err = 0;           // the adapted lighting against the truth at the last frame
  double settled_after_s = -1;  // from the change until the error stays within 5 %
  double worst_step = 0;        // largest frame-to-frame change of the object's brightness
  int bakes = 0;
};

Followed follow(const std::filesystem::path& recording, const sim::LightChange& change) {
  pipeline::ReplayOverlaySettings rs;
  rs.poses = pipeline::PoseSource::Truth;
  rs.overlay.features = kNoFeatures;
  rs.overlay.adapt_lighting_every = 2;
  rs.overlay.volume_cache = false;
  pipeline::ReplayOverlay replay(recording, rs);
  const LoadedScene& scene = replay.scene();
  const Samples samples = object_samples(scene.objects.front());
  const auto captured = irradiance(*replay.compositor().irradiance_volume(), samples);
  LoadedScene changed = scene;
  changed.map = sim::changed_environment_map(scene, change);
  const auto truth = irradiance(scene_irradiance_volume(changed, scene.manifest.lighting.method, false), samples);

  Followed f;
  f.baseline_err = relative_error(captured, truth);
  double previous = brightness(captured);
  std::vector<std::pair<double, double>> errors;  // (time, error against the truth) after the change
  replay.run(0, [&](const pipeline::OverlayFrame& frame) {
    const auto e = irradiance(*replay.compositor().irradiance_volume(), samples);
    const double t = nanos_to_seconds(frame.time);
    f.worst_step = std::max(f.worst_step, std::abs(brightness(e) / previous - 1.0));
    previous = brightness(e);
    if (t < change.at_s)
      f.before_err = std::max(f.before_err, relative_error(e, captured));
    else
      errors.emplace_back(t, relative_error(e, truth));
    return true;
  });
  f.end_err = errors.back().second;
  for (std::size_t k = errors.size(); k-- > 0;)
    if (errors[k].second > 0.05) {
      if (k + 1 < errors.size()) f.settled_after_s = errors[k + 1].first - change.at_s;
      break;
    } else if (k == 0) {
      f.settled_after_s = errors[0].first - change.at_s;
    }
  f.bakes = replay.live_lighting()->bakes();
  std::printf(
      "without adapting %.1f %%; adapted: %.1f %% before the change (against the captured map), %.1f %% at the end, "
      "within 5 %% from %.2f s after the change; largest step in brightness %.2f %%; %d re-bakes\n",
      100 * f.baseline_err, 100 * f.before_err, 100 * f.end_err, f.settled_after_s, 100 * f.worst_step, f.bakes);
  return f;
}

void expect_followed(const Followed& f) {
  EXPECT_GT(f.baseline_err, 0.06) << "the change should matter to the object more than the tolerance";
  EXPECT_LT(f.end_err, 0.05);
  EXPECT_GE(f.settled_after_s, 0.0) << "never within 5 % of the changed map's lighting";
  EXPECT_LE(f.settled_after_s, 3.0);
  EXPECT_LE(f.worst_step, 0.02) << "the object's brightness popped";
  EXPECT_LT(f.before_err, 0.05) << "adapting changed the lighting of a room that had not changed";
}

TEST(LightingChange, ALampGoingOutIsFollowedWithinThreeSecondsWithoutAPop) {
  const test::Scratch scratch("lighting-change-lamp");
  const auto change = lamp_off();
  expect_followed(follow(record(scratch.dir / "lamp-off", change, 120), change));
}

TEST(LightingChange, AWindowTurningWarmerIsFollowedPerColour) {
  const test::Scratch scratch("lighting-change-window");
  const auto change = warmer_window();
  expect_followed(follow(record(scratch.dir / "warmer-window", change, 96, kWindowExposure), change));
}

}  // namespace
}  // namespace lumar
