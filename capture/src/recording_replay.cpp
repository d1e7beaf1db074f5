#include "lumar/capture/recording_replay.h"

#include <algorithm>

#include <fmt/format.h>

#include "lumar/base/error.h"
#include "lumar/tracking/tracker_stream.h"

namespace lumar::capture {

RecordingReplay::RecordingReplay(const std::filesystem::path& dir,
                                 const std::optional<tracking::PoseFilterSettings>& filter)
    : reader_(dir), session_(reader_.session()) {
  // Intrinsics of another size would project every pose to the wrong pixels.
  const cv::Size video = reader_.video().size;
  if (session_.camera.width != video.width || session_.camera.height != video.height)
    throw InputError((dir / kSessionFile).string() + ": the camera is " + std::to_string(session_.camera.width) + "x" +
                     std::to_string(session_.camera.height) + " but the video is " + std::to_string(video.width) + "x" +
                     std::to_string(video.height) + "; give the calibration of the camera that recorded it");
  const TrackerSettings& t = session_.tracker;
  std::size_t ignored = 0;
  const auto chunks = reader_.tracker_chunks(&ignored, &stats_.torn_bytes);
  stats_.damaged_bytes = ignored - stats_.torn_bytes;
  const auto decoded = tracking::decode_tracker_stream(chunks, tracker_format_of(t, (dir / kSessionFile).string()),
                                                       t.baud, session_.rig.latency);
  std::optional<tracking::PoseSampleFilter> filtered;
  if (filter) filtered.emplace(*filter);
  for (const auto& sample : decoded.samples)
    if (sample.station == t.station) poses_.add(filtered ? filtered->filter(sample) : sample);
  stats_.records = decoded.records;
  stats_.rejected_records = decoded.rejected_records;
  stats_.skipped_bytes = decoded.skipped_bytes;
  std::error_code ec;
  stats_.stream_bytes = std::size_t(std::filesystem::file_size(dir / kTrackerFile, ec));
  if (ec) stats_.stream_bytes = 0;
  if (stats_.lost_fraction() > kTrackerLossWarning)
    tracker_loss_ = fmt::format(
        "{}: {} of {} bytes ({:.1f} %) of the tracker stream lost: {} in damaged chunks, {} the {} parser skipped "
        "({} records rejected); {} records read. Poses are missing where the bytes were",
        (dir / kTrackerFile).string(), stats_.lost_bytes(), stats_.stream_bytes, 100.0 * stats_.lost_fraction(),
        stats_.damaged_bytes, stats_.skipped_bytes, t.device, stats_.rejected_records, stats_.records);
  truth_ = reader_.truth();
}

std::filesystem::path RecordingReplay::scene_path() const {
  if (session_.scene.empty()) return {};
  return (reader_.directory() / session_.scene).lexically_normal();
}

std::optional<Pose> RecordingReplay::tracked_camera_pose(Nanos t) const {
  const auto sensor = poses_.at(t, session_.tracker.station);
  if (!sensor) return std::nullopt;
  return session_.rig.camera_pose(*sensor);
}

std::optional<Pose> RecordingReplay::true_camera_pose(std::int64_t index) const {
  for (const auto& e : truth_)
    if (e.index == index) return e.T_world_camera;
  return std::nullopt;
}

std::optional<Pose> RecordingReplay::true_camera_pose_at(Nanos t) const {
  if (truth_.empty()) return std::nullopt;
  if (truth_.size() == 1) return truth_[0].T_world_camera;
  // truth.csv lists the frames in their order, so in time order.
  const auto after = std::lower_bound(truth_.begin(), truth_.end(), t,
                                      [](const TruthEntry& e, Nanos time) { return e.time < time; });
  const std::size_t j = std::clamp<std::size_t>(std::size_t(after - truth_.begin()), 1, truth_.size() - 1);
  const TruthEntry &a = truth_[j - 1], &b = truth_[j];
  if (b.time == t) return b.T_world_camera;
  if (b.time == a.time || a.time == t) return a.T_world_camera;
  const double s = double(t - a.time) / double(b.time - a.time);
  Pose p = interpolate(a.T_world_camera, b.T_world_camera, s);
  // The position on a Catmull-Rom spline through the frames around t, evenly apart (at
  // the recording's ends, through a point the parabola through the last three frames
  // puts beyond them). A camera's path is a curve, and a chord cuts it by its sagitta: an
  // orbit turning 20 degrees a frame, by 1.5 % of its radius.
  const Nanos period = b.time - a.time;
  const auto evenly = [&](std::size_t i, std::size_t k) { return truth_[k].time - truth_[i].time == period; };
  const auto at = [&](std::size_t i) { return truth_[i].T_world_camera.translation; };
  const std::size_t n = truth_.size();
  const bool first = j < 2, last = j + 1 >= n;
  if (n >= 3 && (first ? evenly(j, j + 1) : evenly(j - 2, j - 1)) && (last ? evenly(j - 2, j - 1) : evenly(j, j + 1))) {
    const glm::dvec3 p1 = at(j - 1), p2 = at(j);
    const glm::dvec3 p0 = first ? 3.0 * p1 - 3.0 * p2 + at(j + 1) : at(j - 2);
    const glm::dvec3 p3 = last ? 3.0 * p2 - 3.0 * p1 + at(j - 2) : at(j + 1);
    p.translation = 0.5 * (2.0 * p1 + (p2 - p0) * s + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s * s +
                           (3.0 * p1 - p0 - 3.0 * p2 + p3) * s * s * s);
  }
  return p;
}

}  // namespace lumar::capture
