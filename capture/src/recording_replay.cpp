#include "lumar/capture/recording_replay.h"

#include "lumar/base/error.h"
#include "lumar/tracking/tracker_stream.h"

namespace lumar::capture {

RecordingReplay::RecordingReplay(const std::filesystem::path& dir,
                                 const std::optional<tracking::PoseFilterSettings>& filter)
    : reader_(dir), session_(reader_.session()) {
  const TrackerSettings& t = session_.tracker;
  const auto decoded = tracking::decode_tracker_stream(reader_.tracker_chunks(&stats_.torn_bytes),
                                                       tracker_format_of(t, (dir / kSessionFile).string()), t.baud,
                                                       session_.rig.latency);
  std::optional<tracking::PoseSampleFilter> filtered;
  if (filter) filtered.emplace(*filter);
  for (const auto& sample : decoded.samples)
    if (sample.station == t.station) poses_.add(filtered ? filtered->filter(sample) : sample);
  stats_.records = decoded.records;
  stats_.rejected_records = decoded.rejected_records;
  stats_.skipped_bytes = decoded.skipped_bytes;
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

}  // namespace lumar::capture
