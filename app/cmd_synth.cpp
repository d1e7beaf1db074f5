// lumar synth: a synthetic recording with ground truth, for regression.
#include <cstdio>
#include <memory>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"
#include "lumar/calib/camera_file.h"
#include "lumar/sim/synthetic_board.h"
#include "lumar/sim/synthetic_recording.h"
#include "lumar/sim/synthetic_sweep.h"

namespace lumar::app {

namespace {
// --sweep: a recording of a map alone, for `lumar envmap` (sim/synthetic_sweep.h).
struct SweepOptions {
  sim::SweepSynthSettings settings;
  std::string envmap, exposures = "0,-5,-10";
  bool sweep = false;
};

void add_sweep_options(CLI::App* cmd, SweepOptions& o) {
  cmd->add_flag("--sweep", o.sweep, "Render a sweep of an environment map alone (for `lumar envmap`); needs --envmap");
  cmd->add_option("--envmap", o.envmap, "--sweep: the lat-long HDR map (OpenEXR or Radiance HDR)");
  cmd->add_option("--exposures", o.exposures, "--sweep: exposures in stops relative to 18 % grey, e.g. 0,-5,-10")
      ->capture_default_str();
  cmd->add_option("--exposure-mode", o.settings.exposure_mode,
                  "--sweep: bracket (stop and take every exposure) or cycle (one exposure per frame while moving)")
      ->check(CLI::IsMember({"bracket", "cycle"}))
      ->capture_default_str();
}
}  // namespace

void register_synth(CLI::App& app) {
  auto s = std::make_shared<sim::SynthSettings>();
  auto camera_file = std::make_shared<std::string>();
  auto* cmd =
      app.add_subcommand("synth", "Render a synthetic recording (video + tracker stream + true poses) of a scene");
  cmd->add_option("--scene", s->scene, "Scene manifest (scene.json); not with --board");
  cmd->add_option("--camera", *camera_file, "Camera calibration (OpenCV YAML) with lens distortion")->required();
  cmd->add_option("--out", s->out, "Recording directory to create (must not exist)")->required();
  cmd->add_option("--frames", s->frames, "Number of video frames")->capture_default_str();
  cmd->add_option("--fps", s->fps, "Video frame rate")->capture_default_str();
  cmd->add_option("--supersample", s->supersample, "Render at this many samples per pixel side")
      ->check(CLI::Range(1, 4))
      ->capture_default_str();
  cmd->add_option("--exposure", s->exposure, "Video linear value per unit radiance (0 = automatic, 18 % grey)")
      ->capture_default_str();
  cmd->add_option("--read-noise", s->read_noise, "Sensor read noise, linear standard deviation")->capture_default_str();
  cmd->add_option("--shot-noise", s->shot_noise_gain, "Sensor shot noise, variance per unit linear signal")
      ->capture_default_str();
  cmd->add_option("--vignetting", s->vignetting_a, "Vignetting gain 1 + a r^2 + b r^4: the a term")
      ->capture_default_str();
  cmd->add_option("--vignetting-b", s->vignetting_b, "Vignetting: the b term")->capture_default_str();
  cmd->add_option("--tracker-noise-deg", s->tracker_noise_deg, "Tracker orientation noise, RMS degrees")
      ->capture_default_str();
  cmd->add_option("--position-noise-m", s->position_noise_m, "Tracker position noise, RMS metres per axis")
      ->capture_default_str();
  cmd->add_option("--latency-ms", s->latency_ms, "Tracker latency in milliseconds")->capture_default_str();
  cmd->add_option("--arc-deg", s->arc_deg, "How far the camera orbits the object, degrees")->capture_default_str();
  cmd->add_option("--path", s->path,
                  "The camera's path: orbit, still (held where the orbit ends), room (standing back, turning slowly "
                  "across the object to the far wall), or rest-turn (held 2 s, turning at 30 deg/s for 1 s, held)")
      ->check(CLI::IsMember({"orbit", "still", "room", "rest-turn"}))
      ->capture_default_str();
  cmd->add_flag("--room-differs", s->room_differs,
                "The video shows a room unlike the scene's proxy: a wall 3 cm off with a recess, a cabinet, a "
                "table, a box; --truth is rendered in it too (the overlay still gets the proxy)");
  // What goes wrong with a real camera's video (sim/video_faults.h).
  auto drop = std::make_shared<std::vector<int>>(), flat = std::make_shared<std::vector<int>>(),
       occluder = std::make_shared<std::vector<int>>();
  cmd->add_option("--drop-frames", *drop, "Leave COUNT frames from frame FROM out of the video: FROM COUNT")
      ->expected(2);
  cmd->add_option("--textureless", *flat, "A flat wall fills the view for COUNT frames from frame FROM: FROM COUNT")
      ->expected(2);
  cmd->add_option("--occluder", *occluder,
                  "A textured panel half the frame wide slides across the view over COUNT frames from FROM: FROM COUNT")
      ->expected(2);
  cmd->add_option("--motion-blur", s->faults.motion_blur_s,
                  "Shutter time in seconds: each frame is blurred by the "
                  "camera's motion over it (0: none)")
      ->capture_default_str();
  cmd->add_option("--codec", s->codec, "Video codec: mjpeg (near-lossless) or ffv1 (lossless)")
      ->check(CLI::IsMember({"mjpeg", "ffv1"}))
      ->capture_default_str();
  cmd->add_option("--quality", s->quality, "MJPEG quality")->check(CLI::Range(50, 100))->capture_default_str();
  cmd->add_option("--seed", s->seed, "Random seed for noise")->capture_default_str();
  cmd->add_flag("--truth", s->truth,
                "Also write truth/: the frames with the scene's objects physically present, by brute force, and "
                "their masks (docs/ground_truth.md)");
  cmd->add_option("--truth-frames", s->truth_frames,
                  "--truth: only these frames get truth, e.g. 0,15,31,47 (default: every frame)")
      ->delimiter(',');
  cmd->add_option("--truth-seed", s->truth_seed,
                  "--truth: the noise seed of the second truth (truth/other-seed-*), the noise floor; 0 = --seed + 1")
      ->capture_default_str();
  cmd->add_option("--truth-strata", s->truth_strata,
                  "--truth: N*N rays per object pixel, N from 2 to 64; the truth's own noise falls as 1/N")
      ->capture_default_str();
  // A change of the room's light during the recording.
  auto change_box = std::make_shared<std::vector<double>>();
  auto change_scale = std::make_shared<std::vector<double>>();
  auto change = std::make_shared<sim::LightChange>();
  cmd->add_option("--change-box", *change_box,
                  "The room's light changes where the map's texels lie on the proxy inside this world box: "
                  "X0 Y0 Z0 X1 Y1 Z1 metres (with --change-scale)")
      ->expected(6);
  cmd->add_option("--change-scale", *change_scale, "--change-box: RGB factor, e.g. 0 0 0 for a lamp going out")
      ->expected(3);
  cmd->add_option("--change-brighter-than", change->brighter_than,
                  "--change-box: only texels of at least this luminance change (a lamp, not the ceiling around it)")
      ->capture_default_str();
  cmd->add_option("--change-at", change->at_s, "--change-box: when, seconds into the recording")->capture_default_str();
  cmd->add_option("--change-ramp", change->ramp_s, "--change-box: how long it takes, seconds (0: at once)")
      ->capture_default_str();
  // --board: the tracked camera filming a checkerboard, for `lumar calibrate-rig`.
  auto b = std::make_shared<sim::BoardSynthSettings>();
  auto board = std::make_shared<std::string>();
  cmd->add_option("--board", *board, "Render a checkerboard recording instead: inner corners WxH, e.g. 9x6");
  cmd->add_option("--square", b->square, "--board: square size in metres")->capture_default_str();
  cmd->add_option("--seconds", b->seconds, "--board: length of the video in seconds")->capture_default_str();
  cmd->add_option("--assumed-latency-ms", b->assumed_latency_ms,
                  "--board: the tracker latency session.json claims (the device's is --latency-ms)")
      ->capture_default_str();
  cmd->add_option("--image-noise", b->image_noise, "--board: image noise, 8-bit levels RMS")->capture_default_str();
  auto sweep = std::make_shared<SweepOptions>();
  add_sweep_options(cmd, *sweep);
  add_action(cmd, [cmd, s, camera_file, b, board, sweep, change_box, change_scale, change, drop, flat, occluder] {
    catch_stop_signals();  // Ctrl-C stops between frames; the unfinished recording is removed
    for (auto [from, range] : {std::pair{drop, &s->faults.dropped}, std::pair{flat, &s->faults.textureless},
                               std::pair{occluder, &s->faults.occluder}})
      if (!from->empty()) *range = sim::FrameRange{(*from)[0], (*from)[1]};
    if (change_box->empty() != change_scale->empty())
      throw InputError("synth: --change-box and --change-scale go together");
    if (!change_box->empty()) {
      const auto& v = *change_box;
      change->region.min = glm::min(glm::dvec3(v[0], v[1], v[2]), glm::dvec3(v[3], v[4], v[5]));
      change->region.max = glm::max(glm::dvec3(v[0], v[1], v[2]), glm::dvec3(v[3], v[4], v[5]));
      change->scale = glm::dvec3((*change_scale)[0], (*change_scale)[1], (*change_scale)[2]);
      if (change->at_s < 0 || change->ramp_s < 0) throw InputError("synth: --change-at and --change-ramp must be >= 0");
      s->light_change = *change;
    }
    if (sweep->sweep) {
      if (sweep->envmap.empty()) throw InputError("synth --sweep: give the map to sweep with --envmap MAP.exr");
      sim::SweepSynthSettings settings = sweep->settings;
      settings.envmap = sweep->envmap;
      settings.exposure_stops = sim::parse_exposure_stops(sweep->exposures);
      s->camera = calib::load_camera_file(*camera_file).intrinsics;
      sim::synthesize_sweep(*s, settings);
      return;
    }
    if (!board->empty()) {
      int w = 0, h = 0;
      char x = 0, extra = 0;
      if (std::sscanf(board->c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 2 || h < 2)
        throw InputError("--board " + *board + ": expected inner corners as WxH, e.g. 9x6");
      b->board = {w, h};
      b->out = s->out;
      b->camera = calib::load_camera_file(*camera_file).intrinsics;
      // Shared options keep the board's own defaults unless given.
      auto given = [cmd](const char* name) { return cmd->get_option(name)->count() > 0; };
      if (given("--fps")) b->fps = s->fps;
      if (given("--tracker-noise-deg")) b->tracker_noise_deg = s->tracker_noise_deg;
      if (given("--position-noise-m")) b->position_noise_m = s->position_noise_m;
      if (given("--latency-ms")) b->latency_ms = s->latency_ms;
      if (given("--codec")) b->codec = s->codec;
      b->seed = s->seed;
      sim::synthesize_board_recording(*b);
      return;
    }
    if (s->scene.empty()) throw InputError("synth: give --scene (or --board for a checkerboard recording)");
    s->camera = calib::load_camera_file(*camera_file).intrinsics;
    sim::synthesize_recording(*s);
  });
}

}  // namespace lumar::app
