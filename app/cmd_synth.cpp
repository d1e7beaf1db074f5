// lumar synth: a synthetic recording with ground truth, for regression.
#include <memory>

#include "commands.h"
#include "lumar/calib/camera_file.h"
#include "synthetic_recording.h"

namespace lumar::app {

void register_synth(CLI::App& app) {
  auto s = std::make_shared<SynthSettings>();
  auto camera_file = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("synth", "Render a synthetic recording (video + tracker stream + true poses) of a scene");
  cmd->add_option("--scene", s->scene, "Scene manifest (scene.json)")->required();
  cmd->add_option("--camera", *camera_file, "Camera calibration (OpenCV YAML) with lens distortion")->required();
  cmd->add_option("--out", s->out, "Recording directory to create (must not exist)")->required();
  cmd->add_option("--frames", s->frames, "Number of video frames")->capture_default_str();
  cmd->add_option("--fps", s->fps, "Video frame rate")->capture_default_str();
  cmd->add_option("--supersample", s->supersample, "Render at this many samples per pixel side")
      ->check(CLI::Range(1, 4))->capture_default_str();
  cmd->add_option("--exposure", s->exposure, "Video linear value per unit radiance (0 = automatic, 18 % grey)")
      ->capture_default_str();
  cmd->add_option("--read-noise", s->read_noise, "Sensor read noise, linear standard deviation")->capture_default_str();
  cmd->add_option("--shot-noise", s->shot_noise_gain, "Sensor shot noise, variance per unit linear signal")
      ->capture_default_str();
  cmd->add_option("--vignetting", s->vignetting_a, "Vignetting gain 1 + a r^2 + b r^4: the a term")->capture_default_str();
  cmd->add_option("--vignetting-b", s->vignetting_b, "Vignetting: the b term")->capture_default_str();
  cmd->add_option("--tracker-noise-deg", s->tracker_noise_deg, "Tracker orientation noise, RMS degrees")
      ->capture_default_str();
  cmd->add_option("--position-noise-m", s->position_noise_m, "Tracker position noise, RMS metres per axis")
      ->capture_default_str();
  cmd->add_option("--latency-ms", s->latency_ms, "Tracker latency in milliseconds")->capture_default_str();
  cmd->add_option("--arc-deg", s->arc_deg, "How far the camera orbits the object, degrees")->capture_default_str();
  cmd->add_option("--codec", s->codec, "Video codec: mjpeg (near-lossless) or ffv1 (lossless)")
      ->check(CLI::IsMember({"mjpeg", "ffv1"}))->capture_default_str();
  cmd->add_option("--quality", s->quality, "MJPEG quality")->check(CLI::Range(50, 100))->capture_default_str();
  cmd->add_option("--seed", s->seed, "Random seed for noise")->capture_default_str();
  add_action(cmd, [s, camera_file] {
    s->camera = calib::load_camera_file(*camera_file).intrinsics;
    synthesize_recording(*s);
  });
}

}  // namespace lumar::app
