#include "lumar/calib/rig_recording.h"

#include <string>

#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/calib/board_pose.h"
#include "lumar/capture/recording_format.h"
#include "lumar/capture/recording_replay.h"

namespace lumar::calib {

namespace {

std::string size_text(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

}  // namespace

RigRecording load_rig_recording(const std::filesystem::path& dir, cv::Size inner_corners, double square_size_m,
                                const std::optional<CameraIntrinsics>& camera, int every) {
  if (inner_corners.width < 2 || inner_corners.height < 2)
    throw InputError("--board " + size_text(inner_corners) + ": give the inner corners, e.g. 9x6");
  if (!(square_size_m > 0)) throw InputError("--square: must be a positive length in metres");
  if (every < 1) throw InputError("--every: must be 1 or more");
  if (!std::filesystem::is_directory(dir))
    throw InputError(dir.string() + ": recording not found; give a recording directory");
  // Frames and tracker stream as a replay sees them (the raw bytes through the real parser).
  const capture::RecordingReplay replay(dir);
  const std::string session_file = (dir / capture::kSessionFile).string();
  RigRecording out;
  out.session = replay.session();
  out.camera = camera ? *camera : out.session.camera;
  const cv::Size video_size = replay.reader().video().size;
  if (!video_size.empty() && (video_size.width != out.camera.width || video_size.height != out.camera.height))
    throw InputError(session_file + ": video is " + size_text(video_size) + " but the camera calibration is " +
                     std::to_string(out.camera.width) + "x" + std::to_string(out.camera.height) +
                     "; use the calibration of this camera mode");
  out.tracker = replay.sensor_poses();
  out.tracker_records = out.tracker.size();
  if (out.tracker_records == 0)
    throw InputError((dir / capture::kTrackerFile).string() + ": no tracker records for station " +
                     std::to_string(out.session.tracker.station) + "; record the tracker while filming the board");

  auto frames = replay.open_frames();
  capture::Frame frame;
  while (frames->read(frame)) {
    if (out.frames++ % every != 0) continue;
    if (frame.image.cols != out.camera.width || frame.image.rows != out.camera.height)
      throw InputError(dir.string() + ": frame " + std::to_string(frame.index) + " is " +
                       size_text(frame.image.size()) + " but the camera calibration is " +
                       std::to_string(out.camera.width) + "x" + std::to_string(out.camera.height));
    // Adaptive thresholding only once the board size has proved right: a wrong --board
    // would otherwise cost a quarter of a second per frame.
    if (auto pose = find_board_pose(frame.image, inner_corners, square_size_m, out.camera, !out.views.empty()))
      out.views.push_back({frame.index, frame.time, pose->T_camera_board, pose->reprojection_rms_px});
  }
  if (out.views.empty())
    throw InputError(dir.string() + ": no " + size_text(inner_corners) + " board found in any of the " +
                     std::to_string(out.frames) + " frames; check --board (inner corners, not squares)");
  return out;
}

nlohmann::json rig_calibration_json(const RigCalibrationResult& r) {
  nlohmann::json warnings = r.warnings;
  return {{"T_sensor_camera", tracking::pose_to_json(r.rig.T_sensor_camera)},
          {"T_world_transmitter", tracking::pose_to_json(r.rig.T_world_transmitter)},
          {"latency_ns", r.rig.latency},
          {"assumed_latency_ns", r.assumed_latency},
          {"time_offset_ns", r.time_offset},
          {"correlation_offset_ns", r.correlation_offset},
          {"peak_correlation", r.peak_correlation},
          {"correlation_at_zero", r.correlation_at_zero},
          {"hand_eye_T_sensor_camera", tracking::pose_to_json(r.hand_eye.T_sensor_camera)},
          {"hand_eye_views", r.hand_eye.views_used.size()},
          {"hand_eye_min_pair_rotation_deg", r.hand_eye.min_pair_rotation_deg},
          {"views_given", r.views_given},
          {"views_used", r.views_used},
          {"views_rejected_pnp", r.views_rejected_pnp},
          {"samples_used", r.samples_used},
          {"samples_rejected_residual", r.samples_rejected_residual},
          {"median_view_rms_px", r.median_view_rms_px},
          {"view_rms_threshold_px", r.view_rms_threshold_px},
          {"rotation_range_deg", r.rotation_range_deg},
          {"residual_rotation_rms_deg", r.rotation_rms_deg},
          {"residual_translation_rms_m", r.translation_rms_m},
          {"sigma_rotation_deg", r.sigma_rotation_deg},
          {"sigma_translation_m", r.sigma_translation_m},
          {"sigma_time_offset_s", r.sigma_time_offset_s},
          {"warnings", warnings}};
}

void save_rig_to_session(const std::filesystem::path& dir, const RigCalibrationResult& result) {
  capture::update_session_file(dir, [&](capture::Session& session) { session.rig = result.rig; },
                               {{"rig_calibration", rig_calibration_json(result)}});
}

}  // namespace lumar::calib
