#include "lumar/pipeline/envmap_recording.h"

#include <memory>

#include <spdlog/spdlog.h>

#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/camera_response.h"
#include "lumar/capture/recording_replay.h"

namespace lumar::pipeline {

// The recording's frames, the tracker's rotation at each frame's time, the exposures
// (session "frame_exposures", cycled, or its one exposure), brackets as groups.
SweepInput recording_sweep_input(const std::string& recording, const std::string& camera_file, int width) {
  const std::filesystem::path dir = recording;
  auto replay = std::make_shared<const capture::RecordingReplay>(dir);
  const capture::RecordingReader& reader = replay->reader();
  const capture::Session& session = replay->session();
  const auto& frames = reader.frames();
  if (frames.empty()) throw InputError(dir.string() + ": the recording has no frames; record a sweep first");

  SweepInput in;
  in.name = dir.string();
  CameraIntrinsics camera = session.camera;
  std::string camera_name = (dir / capture::kSessionFile).string();
  if (!camera_file.empty()) {
    camera = calib::load_camera_file(camera_file).intrinsics;
    camera_name = camera_file;
  }
  const cv::Size size = reader.video().size;
  if (camera.width != size.width || camera.height != size.height)
    throw InputError(camera_name + ": the calibration is for " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " but the recording's frames are " + std::to_string(size.width) +
                     "x" + std::to_string(size.height) + "; use the calibration of the camera that recorded it");
  if (replay->tracker_stats().records == 0)
    throw InputError(dir.string() + ": the recording has no tracker poses; a sweep needs the tracker's stream");
  if (const auto& loss = replay->tracker_loss(); !loss.empty()) spdlog::warn("{}", loss);

  glm::dvec3 mean_position(0.0);
  for (const auto& f : frames) {
    const auto pose = replay->tracked_camera_pose(f.time);
    if (!pose)
      throw InputError(dir.string() + ": the tracker poses do not cover frame " + std::to_string(f.index) + " at " +
                       std::to_string(nanos_to_seconds(f.time)) +
                       " s; the tracker must run from before the first frame to after the last");
    in.rotations.push_back(pose->rotation);
    in.labels.push_back(std::to_string(f.index) + "," + std::to_string(f.time));
    mean_position += pose->translation / double(frames.size());
  }
  in.label_header = "index,time_ns";

  const std::size_t cycle = std::max<std::size_t>(1, session.frame_exposures.size());
  for (const auto& f : frames) {
    in.exposures.push_back(session.frame_exposure(f.index));
    if (session.exposure_bracket) in.groups.push_back(int(f.index / std::int64_t(cycle)));
  }

  calib::StitchSettings& st = in.stitch;
  st.width = width;
  st.camera = camera;
  st.response = calib::calibrated_response(session.radiometry, dir).value_or(calib::srgb_response(1.0));
  st.vignetting_a = session.radiometry.vignetting_a;
  st.vignetting_b = session.radiometry.vignetting_b;
  st.capture_position = mean_position;
  if (session.envmap) {
    if (session.envmap->capture_position) st.capture_position = *session.envmap->capture_position;
    st.azimuth_offset_deg = session.envmap->azimuth_offset_deg;
    // The map a synthetic sweep was made from: the output is compared with it.
    const std::string& source_map = session.envmap->source_map;
    if (std::error_code ec; !source_map.empty() && std::filesystem::exists(source_map, ec))
      in.default_reference = source_map;
  }
  if (session.synth) in.tracker_noise_deg = session.synth->tracker_noise_deg;

  if (!reader.truth().empty())
    for (const auto& f : frames) {
      const auto truth = replay->true_camera_pose(f.index);
      in.truth.push_back(truth ? std::optional<glm::dquat>(truth->rotation) : std::nullopt);
    }
  const int n = int(frames.size());
  in.read_frames = [replay, n](const std::function<void(const cv::Mat&, int)>& use) {
    auto source = replay->open_frames();
    capture::Frame frame;
    for (int k = 0; k < n && source->read(frame); ++k) use(frame.image, k);
  };
  return in;
}

}  // namespace lumar::pipeline
