#include "sweep_fixture.h"

#include <cmath>
#include <map>
#include <mutex>
#include <random>

#include "lumar/calib/camera_file.h"
#include "lumar/envmap/orientation_refinement.h"
#include "lumar/envmap/sweep_path.h"
#include "test_paths.h"

namespace lumar::test {

CameraIntrinsics webcam() {
  return calib::load_camera_file(source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
}

double auto_exposure(const EnvironmentMap& map) { return 0.18 / mean_luminance(map); }

double rms_angle_deg(const std::vector<glm::dquat>& a, const std::vector<glm::dquat>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += std::pow(rotation_angle_deg(a[i], b[i]), 2);
  return std::sqrt(sum / a.size());
}

namespace {
std::string key_of(const SweepSpec& spec) {
  std::string key = spec.map + "/" + std::to_string(spec.frames) + "/" + std::to_string(spec.tracker_noise_deg) + "/" +
                    std::to_string(spec.seed);
  for (double s : spec.exposure_stops) key += "/" + std::to_string(s);
  return key;
}
}  // namespace

const calib::RefinementResult& refined_sweep(const SweepSpec& spec) {
  static std::mutex mutex;
  static std::map<std::string, calib::RefinementResult> cache;
  const Sweep& sweep = synthetic_sweep(spec);
  std::lock_guard lock(mutex);
  const std::string key = key_of(spec);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  std::vector<calib::FrameFeatures> features;
  for (const auto& f : sweep.frames)
    features.push_back(calib::extract_frame_features(f, sweep.camera, calib::srgb_response(1.0)));
  return cache.emplace(key, calib::refine_orientations(features, sweep.tracker, {}, sweep.groups)).first->second;
}

const Sweep& synthetic_sweep(const SweepSpec& spec) {
  static std::mutex mutex;
  static std::map<std::string, Sweep> cache;
  const std::string key = key_of(spec);
  std::lock_guard lock(mutex);
  if (auto it = cache.find(key); it != cache.end()) return it->second;

  Sweep sweep;
  sweep.source = load_environment_map(shared_dir() / "data/envmaps" / (spec.map + ".exr"));
  sweep.camera = webcam();
  const sim::EnvmapViewRenderer view(sweep.camera);
  const double base = auto_exposure(sweep.source);
  std::mt19937_64 random(spec.seed);
  std::normal_distribution<double> normal(0.0, glm::radians(spec.tracker_noise_deg) / std::sqrt(3.0));
  cv::RNG rng(spec.seed);
  for (int k = 0; k < spec.frames; ++k) {
    const int n = int(spec.exposure_stops.size()), stations = (spec.frames + n - 1) / n;
    const glm::dquat truth = calib::sweep_rotation((k / n + 0.5) / stations);
    sweep.groups.push_back(k / n);
    const double exposure = base * std::exp2(spec.exposure_stops[k % spec.exposure_stops.size()]);
    const glm::dvec3 noise(normal(random), normal(random), normal(random));
    sweep.truth.push_back(truth);
    sweep.tracker.push_back(glm::normalize(rotation_exp(noise) * truth));
    sweep.exposures.push_back(exposure);
    sweep.frames.push_back(
        sim::expose_8bit(view.render(sweep.source, truth), sweep.camera, sweep.sensor, exposure, rng));
  }
  return cache.emplace(key, std::move(sweep)).first->second;
}

}  // namespace lumar::test
