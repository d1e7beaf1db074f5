#include "lumar/capture/recording_replay.h"

#include "lumar/base/error.h"
#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/record_parser.h"
#include "lumar/tracking/timestamping.h"

namespace lumar::capture {

RecordingReplay::RecordingReplay(const std::filesystem::path& dir)
    : reader_(dir), session_(session_from_json(reader_.session(), (dir / "session.json").string())) {
  const TrackerSettings& t = session_.tracker;
  const std::string session_file = (dir / "session.json").string();
  if (t.encoding != "ascii" && t.encoding != "binary")
    throw InputError(session_file + ": tracker encoding '" + t.encoding + "' is unknown; use ascii or binary");
  tracking::TrackerFormat tracker_format;
  try {
    tracker_format = tracking::TrackerFormat::of(tracking::parse_device(t.device), t.encoding == "binary",
                                                 {t.output_list, t.centimetres});
    tracking::validate_tracker_format(tracker_format);
  } catch (const InputError& e) {
    throw InputError(session_file + ": " + e.what());
  }
  const tracking::OutputFormat& format = tracker_format.output;
  tracking::RecordParser parser(tracker_format, t.baud);
  for (const auto& chunk : reader_.tracker_chunks(&stats_.torn_bytes)) {
    parser.push(chunk);
    for (const auto& r : parser.take_all()) {
      if (r.record.station != t.station) continue;
      const Nanos time = tracking::measurement_time(r.first_byte_arrival, t.baud, session_.rig.latency);
      if (auto sample = tracking::to_pose_sample(r.record, format, time)) poses_.add(*sample);
    }
  }
  stats_.records = parser.accepted_records();
  stats_.rejected_records = parser.rejected_records();
  stats_.skipped_bytes = parser.skipped_bytes();
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
