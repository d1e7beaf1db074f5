#include "lumar/capture/frame_pose_pairing.h"

#include <algorithm>

namespace lumar::capture {

FramePosePairing::FramePosePairing(tracking::Rig rig, int station, tracking::PoseLookupSettings lookup)
    : rig_(rig), station_(station), lookup_(lookup) {}

void FramePosePairing::add(const tracking::PoseSample& sample) {
  std::lock_guard lock(mutex_);
  stream_.add(sample);
}

void FramePosePairing::add(const std::vector<tracking::PoseSample>& samples) {
  std::lock_guard lock(mutex_);
  for (const auto& s : samples) stream_.add(s);
}

PairedFrame FramePosePairing::pair(Frame frame) const {
  PairedFrame out;
  {
    std::lock_guard lock(mutex_);
    out.sensor = stream_.lookup(frame.time, station_, lookup_);
  }
  if (out.sensor.pose) out.T_world_camera = rig_.camera_pose(*out.sensor.pose);
  out.frame = std::move(frame);
  return out;
}

std::optional<Pose> FramePosePairing::camera_at(Nanos t) const {
  std::optional<Pose> sensor;
  {
    std::lock_guard lock(mutex_);
    sensor = stream_.lookup(t, station_, lookup_).pose;
  }
  if (!sensor) return std::nullopt;
  return rig_.camera_pose(*sensor);
}

bool FramePosePairing::covers(Nanos t) const {
  std::lock_guard lock(mutex_);
  const auto& s = stream_.samples(station_);
  return !s.empty() && s.back().time >= t + lookup_.time_offset;
}

void FramePosePairing::forget_before(Nanos t) {
  std::lock_guard lock(mutex_);
  const auto& s = stream_.samples(station_);
  // PoseStream has no erase: rebuild it from what stays (rare, cheap at 60 Hz).
  auto first_kept = std::lower_bound(s.begin(), s.end(), t + lookup_.time_offset,
                                     [](const tracking::PoseSample& a, Nanos v) { return a.time < v; });
  if (first_kept == s.begin()) return;
  --first_kept;
  tracking::PoseStream kept;
  for (int st : stream_.stations()) {
    for (const auto& x : stream_.samples(st))
      if (st != station_ || x.time >= first_kept->time) kept.add(x);
  }
  stream_ = std::move(kept);
}

std::size_t FramePosePairing::samples() const {
  std::lock_guard lock(mutex_);
  return stream_.size();
}

}  // namespace lumar::capture
