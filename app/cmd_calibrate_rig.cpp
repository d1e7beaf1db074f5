// lumar calibrate-rig: tracker-to-camera offset, transmitter alignment and latency from a
// recording of the tracked camera filming a checkerboard; written into its session.json.
#include <spdlog/spdlog.h>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/rig_recording.h"

namespace lumar::app {

namespace {

struct CalibrateRigOptions {
  std::string recording;
  std::string board = "9x6";
  double square = 0.025;
  std::string camera;
  int every = 1;
  bool json = false;
  bool dry_run = false;
  double max_offset_ms = 1000;
  bool fixed_latency = false;
  calib::RigCalibrationOptions calib;
};

cv::Size parse_board_size(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 2 || h < 2)
    throw InputError("--board " + text + ": expected inner corners as WxH, e.g. 9x6");
  return {w, h};
}

double deg(const glm::dquat& q) { return glm::degrees(2.0 * std::acos(std::min(1.0, std::abs(q.w)))); }

}  // namespace

void register_calibrate_rig(CLI::App& app) {
  auto o = std::make_shared<CalibrateRigOptions>();
  auto* cmd = app.add_subcommand("calibrate-rig",
                                 "Tracker-to-camera offset, transmitter alignment and latency from a recording of "
                                 "the tracked camera filming a checkerboard (writes them into session.json)");
  cmd->add_option("--recording", o->recording, "Recording directory (lumar tracker record / lumar synth --board)")
      ->required();
  cmd->add_option("--board", o->board, "Inner corners of the board, WxH")->capture_default_str();
  cmd->add_option("--square", o->square, "Square size in metres")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--camera", o->camera, "Camera calibration (OpenCV YAML); default: the session's camera");
  cmd->add_option("--every", o->every, "Use every Nth frame")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--max-offset-ms", o->max_offset_ms, "Search the tracker-video time offset within +- this")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("--fixed-latency", o->fixed_latency, "Keep the session's latency (do not estimate the time offset)");
  cmd->add_option("--tracker-rotation-sigma-deg", o->calib.tracker_rotation_sigma_deg,
                  "Tracker orientation noise, RMS degrees (weights the fit)")
      ->capture_default_str();
  cmd->add_option("--tracker-position-sigma-m", o->calib.tracker_position_sigma_m,
                  "Tracker position noise, RMS metres per axis (weights the fit)")
      ->capture_default_str();
  cmd->add_flag("--dry-run", o->dry_run, "Report only; leave session.json as it is");
  cmd->add_flag("--json", o->json, "Print a machine-readable summary to stdout");
  add_action(cmd, [o] {
    const cv::Size board = parse_board_size(o->board);
    std::optional<CameraIntrinsics> camera;
    if (!o->camera.empty()) camera = calib::load_camera_file(o->camera).intrinsics;
    const calib::RigRecording rec = calib::load_rig_recording(o->recording, board, o->square, camera, o->every);
    auto options = o->calib;
    options.estimate_time_offset = !o->fixed_latency;
    options.time_offset.max_offset = seconds_to_nanos(o->max_offset_ms * 1e-3);
    calib::RigCalibrationResult result;
    try {
      result =
          calib::calibrate_rig(rec.views, rec.tracker, rec.session.tracker.station, rec.session.rig.latency, options);
    } catch (const InputError& e) {
      throw InputError(o->recording + ": " + e.what());
    }
    if (!o->dry_run) calib::save_rig_to_session(o->recording, result);
    for (const auto& w : result.warnings) std::fprintf(stderr, "lumar: warning: %s\n", w.c_str());
    if (o->json) {
      nlohmann::json j = calib::rig_calibration_json(result);
      j["frames"] = rec.frames;
      j["views_with_board"] = rec.views.size();
      j["tracker_records"] = rec.tracker_records;
      j["session_updated"] = !o->dry_run;
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    const auto& x = result.rig.T_sensor_camera;
    const auto& w = result.rig.T_world_transmitter;
    spdlog::info(
        "calibrate-rig: board in {} of {} frames; {} views used ({} rejected for PnP error > {:.2f} px); "
        "{} tracker samples fitted ({} rejected by the fit); camera turned {:.0f} deg",
        rec.views.size(), rec.frames, result.views_used, result.views_rejected_pnp, result.view_rms_threshold_px,
        result.samples_used, result.samples_rejected_residual, result.rotation_range_deg);
    spdlog::info(
        "  latency {:.2f} ms (assumed {:.2f} ms; offset {:+.2f} ms +- {:.2f}, cross-correlation {:+.2f} ms, "
        "peak r = {:.3f}, r at 0 = {:.3f})",
        nanos_to_seconds(result.rig.latency) * 1e3, nanos_to_seconds(result.assumed_latency) * 1e3,
        nanos_to_seconds(result.time_offset) * 1e3, result.sigma_time_offset_s * 1e3,
        nanos_to_seconds(result.correlation_offset) * 1e3, result.peak_correlation, result.correlation_at_zero);
    spdlog::info("  T_sensor_camera: t = ({:.4f}, {:.4f}, {:.4f}) m +- {:.2f} mm, rotation {:.2f} deg +- {:.3f} deg",
                 x.translation.x, x.translation.y, x.translation.z, result.sigma_translation_m * 1e3, deg(x.rotation),
                 result.sigma_rotation_deg);
    spdlog::info(
        "  T_world_transmitter: t = ({:.4f}, {:.4f}, {:.4f}) m, rotation {:.2f} deg (world = board frame, "
        "+Y out of its face)",
        w.translation.x, w.translation.y, w.translation.z, deg(w.rotation));
    spdlog::info(
        "  residuals: {:.3f} deg, {:.2f} mm RMS (tracker against board); cv::calibrateHandEye alone differs "
        "by {:.2f} mm, {:.3f} deg",
        result.rotation_rms_deg, result.translation_rms_m * 1e3,
        1e3 * glm::length(result.hand_eye.T_sensor_camera.translation - x.translation),
        rotation_angle_deg(result.hand_eye.T_sensor_camera.rotation, x.rotation));
    spdlog::info("  {} {}", o->dry_run ? "dry run, not written to" : "written to", o->recording + "/session.json");
  });
}

}  // namespace lumar::app
