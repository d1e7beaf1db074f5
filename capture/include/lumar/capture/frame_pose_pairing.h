#pragma once
// Pairs camera frames with the tracker's pose at each frame's exposure time.
//
// Frame times are the middle of the exposure; tracker samples carry their
// measurement time (the driver or the replay already removed the device latency and
// the serial transmission time, see tracking/timestamping.h). What is left is the
// residual offset between the two clocks, `lookup.time_offset` (positive: use later
// tracker data), calibrated by calib's latency estimation. The pose between samples
// comes from tracking::PoseStream (slerp/lerp), with its bounded extrapolation and
// dropout rules.
//
// Thread-safe: a tracker thread may add() while a render or record thread pairs.
#include <cstddef>
#include <mutex>
#include <optional>
#include <vector>

#include "lumar/base/pose.h"
#include "lumar/capture/frame_source.h"
#include "lumar/tracking/pose_stream.h"
#include "lumar/tracking/rig.h"

namespace lumar::capture {

struct PairedFrame {
  Frame frame;
  tracking::PoseLookup sensor;         // T_transmitter_sensor at the frame's time, and why not
  std::optional<Pose> T_world_camera;  // the rig applied to it (nullopt: no pose)
};

class FramePosePairing {
 public:
  FramePosePairing(tracking::Rig rig, int station = 1, tracking::PoseLookupSettings lookup = {});

  void add(const tracking::PoseSample& sample);
  void add(const std::vector<tracking::PoseSample>& samples);

  // The pose at frame.time (+ time_offset).
  PairedFrame pair(Frame frame) const;
  // The camera pose at any time t (+ time_offset), as pair() gives it at a frame's: the
  // other instants of a frame's shutter.
  std::optional<Pose> camera_at(Nanos t) const;
  // Whether a sample at or after t + time_offset has arrived: pairing now interpolates
  // rather than extrapolates. A live loop holds a frame (briefly) until this is true.
  bool covers(Nanos t) const;
  // Forget samples older than t (keeps the one just before, for interpolation); keeps
  // a long live session's memory bounded.
  void forget_before(Nanos t);

  std::size_t samples() const;
  const tracking::Rig& rig() const { return rig_; }

 private:
  const tracking::Rig rig_;
  const int station_;
  const tracking::PoseLookupSettings lookup_;
  mutable std::mutex mutex_;
  tracking::PoseStream stream_;
};

}  // namespace lumar::capture
