#include "lumar/tracking/pose_stream.h"

#include <algorithm>
#include <cmath>

namespace lumar::tracking {

namespace {
bool earlier(const PoseSample& a, const PoseSample& b) { return a.time < b.time; }
}  // namespace

void PoseStream::add(const PoseSample& sample) {
  auto& v = by_station_[sample.station];
  if (v.empty() || v.back().time <= sample.time) {
    v.push_back(sample);
    return;
  }
  v.insert(std::upper_bound(v.begin(), v.end(), sample, earlier), sample);
}

std::optional<Pose> PoseStream::at(Nanos t, int station, Nanos max_gap) const {
  const auto found = by_station_.find(station);
  if (found == by_station_.end()) return std::nullopt;
  const auto& v = found->second;
  PoseSample key;
  key.time = t;
  // First sample at or after t.
  const auto b = std::lower_bound(v.begin(), v.end(), key, earlier);
  if (b == v.end()) return std::nullopt;
  if (b->time == t) return b->T_transmitter_sensor;
  if (b == v.begin()) return std::nullopt;
  const auto a = std::prev(b);
  const Nanos gap = b->time - a->time;
  if (gap > max_gap) return std::nullopt;
  const double s = double(t - a->time) / double(gap);
  return interpolate(a->T_transmitter_sensor, b->T_transmitter_sensor, s);
}

const char* to_string(PoseStatus status) {
  switch (status) {
    case PoseStatus::Interpolated:
      return "interpolated";
    case PoseStatus::Extrapolated:
      return "extrapolated";
    case PoseStatus::NoSamples:
      return "no samples";
    case PoseStatus::BeforeFirst:
      return "before the first sample";
    case PoseStatus::Gap:
      return "in a dropout";
    case PoseStatus::TooOld:
      return "tracker data too old";
  }
  return "?";
}

PoseLookup PoseStream::lookup(Nanos t, int station, const PoseLookupSettings& settings) const {
  t += settings.time_offset;
  PoseLookup out;
  const auto found = by_station_.find(station);
  if (found == by_station_.end() || found->second.empty()) return out;
  const auto& v = found->second;
  const PoseSample& last = v.back();
  out.age = t - last.time;
  if (t < v.front().time) {
    out.status = PoseStatus::BeforeFirst;
    return out;
  }
  if (t <= last.time) {
    out.pose = at(t, station, settings.max_gap);
    out.status = out.pose ? PoseStatus::Interpolated : PoseStatus::Gap;
    return out;
  }
  if (t - last.time > settings.max_extrapolation) {
    out.status = PoseStatus::TooOld;
    return out;
  }
  out.status = PoseStatus::Extrapolated;
  out.pose = last.T_transmitter_sensor;
  if (v.size() < 2) return out;  // no velocity known: hold
  const PoseSample& prev = v[v.size() - 2];
  const Nanos dt = last.time - prev.time;
  if (dt <= 0 || dt > settings.max_gap) return out;
  const double s = double(t - last.time) / double(dt);
  // Rotation: the step prev -> last (in the transmitter frame), taken s times more.
  glm::dquat step = last.T_transmitter_sensor.rotation * glm::inverse(prev.T_transmitter_sensor.rotation);
  if (step.w < 0) step = -step;
  const double half = std::atan2(glm::length(glm::dvec3(step.x, step.y, step.z)), step.w);
  if (half > 0) {
    const glm::dvec3 axis = glm::normalize(glm::dvec3(step.x, step.y, step.z));
    out.pose->rotation = glm::normalize(glm::angleAxis(2 * half * s, axis) * last.T_transmitter_sensor.rotation);
  }
  out.pose->translation += s * (last.T_transmitter_sensor.translation - prev.T_transmitter_sensor.translation);
  return out;
}

std::size_t PoseStream::size() const {
  std::size_t n = 0;
  for (const auto& [station, v] : by_station_) n += v.size();
  return n;
}

const std::vector<PoseSample>& PoseStream::samples(int station) const {
  static const std::vector<PoseSample> kNone;
  const auto found = by_station_.find(station);
  return found == by_station_.end() ? kNone : found->second;
}

std::vector<int> PoseStream::stations() const {
  std::vector<int> out;
  for (const auto& [station, v] : by_station_) out.push_back(station);
  return out;
}

}  // namespace lumar::tracking
