#pragma once
// Replays a recording as the live system would see it: frames from the video, camera
// poses from the raw tracker bytes run through the real protocol parser, time-aligned
// with the rig's latency. Ground truth, where the recording has it, sits beside.
#include <filesystem>
#include <memory>
#include <optional>

#include "lumar/capture/frame_source.h"
#include "lumar/capture/recording_reader.h"
#include "lumar/capture/session.h"
#include "lumar/tracking/one_euro_filter.h"
#include "lumar/tracking/pose_stream.h"

namespace lumar::capture {

struct TrackerReplayStats {
  std::size_t stream_bytes = 0;  // tracker.raw's size
  std::size_t records = 0, rejected_records = 0;
  std::size_t skipped_bytes = 0;  // in whole chunks, that the protocol parser could not read
  std::size_t damaged_bytes = 0;  // in damaged chunks (tracker_raw.h)
  std::size_t torn_bytes = 0;     // a last chunk cut short by a crash: expected, not a loss
  std::size_t lost_bytes() const { return skipped_bytes + damaged_bytes; }
  double lost_fraction() const { return stream_bytes ? double(lost_bytes()) / double(stream_bytes) : 0.0; }
};

// Loss above this share of the tracker stream is warned about (a torn last chunk is not).
inline constexpr double kTrackerLossWarning = 0.01;

class RecordingReplay {
 public:
  // Throws InputError naming the file when the recording or its session is unusable.
  // `filter`: the tracker's samples pass through it in the order they arrived, as on the
  // live path (tracking/one_euro_filter.h).
  explicit RecordingReplay(const std::filesystem::path& dir,
                           const std::optional<tracking::PoseFilterSettings>& filter = std::nullopt);

  const RecordingReader& reader() const { return reader_; }
  const Session& session() const { return session_; }
  // The scene manifest named by the session, resolved against the recording (empty if none).
  std::filesystem::path scene_path() const;
  std::unique_ptr<FrameSource> open_frames() const { return reader_.open_frames(); }

  // T_world_camera from the tracker at time t (recording time); nullopt where the tracker
  // stream does not cover t.
  std::optional<Pose> tracked_camera_pose(Nanos t) const;
  // True T_world_camera of frame `index`, where the recording has ground truth.
  std::optional<Pose> true_camera_pose(std::int64_t index) const;
  // True T_world_camera at time t, interpolated between the two truth entries around it
  // (beyond the first or the last, extrapolated from the two nearest); nullopt without truth.
  std::optional<Pose> true_camera_pose_at(Nanos t) const;
  // T_transmitter_sensor of the session's station, timed with the rig's latency.
  const tracking::PoseStream& sensor_poses() const { return poses_; }
  const TrackerReplayStats& tracker_stats() const { return stats_; }
  // A warning to show when more than kTrackerLossWarning of the tracker stream was lost
  // ("" otherwise): how much, where, and what it means.
  const std::string& tracker_loss() const { return tracker_loss_; }

 private:
  RecordingReader reader_;
  Session session_;
  tracking::PoseStream poses_;
  std::vector<TruthEntry> truth_;
  TrackerReplayStats stats_;
  std::string tracker_loss_;
};

}  // namespace lumar::capture
