#include "lumar/tracking/one_euro_filter.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "lumar/base/error.h"

namespace lumar::tracking {

namespace {

double smoothing(double cutoff_hz, double dt) {
  const double r = 2 * std::numbers::pi * cutoff_hz * dt;
  return r / (1 + r);
}

}  // namespace

void validate_one_euro(const OneEuroSettings& s, const char* what) {
  if (!(std::isfinite(s.min_cutoff_hz) && s.min_cutoff_hz > 0) ||
      !(std::isfinite(s.d_cutoff_hz) && s.d_cutoff_hz > 0) || !(std::isfinite(s.beta) && s.beta >= 0))
    throw InputError(std::string(what) +
                     ": One Euro cutoffs must be > 0 Hz and beta >= 0; e.g. min_cutoff 1, beta 0.5, d_cutoff 1");
}

OneEuroPoseFilter::OneEuroPoseFilter(PoseFilterSettings settings) : settings_(settings) {
  validate_one_euro(settings_.position, "position filter");
  validate_one_euro(settings_.rotation, "rotation filter");
}

Pose OneEuroPoseFilter::filter(const Pose& pose, Nanos time) {
  if (!state_) {
    state_ = State{time, pose, glm::dvec3(0.0), glm::dvec3(0.0)};
    return pose;
  }
  State& s = *state_;
  if (time <= s.time) return s.out;
  const double dt = nanos_to_seconds(time - s.time);
  const OneEuroSettings& P = settings_.position;
  const OneEuroSettings& R = settings_.rotation;

  // Velocities are filtered as vectors, so that noise at rest averages out instead of
  // adding up as |noise| / dt and raising the cutoff of a still camera.
  const glm::dvec3 dx = pose.translation - s.out.translation;
  s.velocity += smoothing(P.d_cutoff_hz, dt) * (dx / dt - s.velocity);
  s.out.translation += smoothing(P.min_cutoff_hz + P.beta * glm::length(s.velocity), dt) * dx;

  glm::dquat target = pose.rotation;
  if (glm::dot(target, s.out.rotation) < 0) target = -target;  // the short way
  const glm::dvec3 w = rotation_log(target * glm::inverse(s.out.rotation)) / dt;
  s.angular_velocity += smoothing(R.d_cutoff_hz, dt) * (w - s.angular_velocity);
  const double a = smoothing(R.min_cutoff_hz + R.beta * glm::length(s.angular_velocity), dt);
  s.out.rotation = glm::normalize(glm::slerp(s.out.rotation, target, a));

  s.time = time;
  return s.out;
}

PoseSample PoseSampleFilter::filter(PoseSample sample) {
  auto it = by_station_.try_emplace(sample.station, settings_).first;
  sample.T_transmitter_sensor = it->second.filter(sample.T_transmitter_sensor, sample.time);
  return sample;
}

std::optional<PoseFilterSettings> parse_pose_filter(const std::string& text, const std::string& option) {
  if (text == "none") return std::nullopt;
  PoseFilterSettings s;
  if (text == "one-euro") return s;
  const std::string prefix = "one-euro:";
  const auto bad = [&] {
    return InputError(option + " " + text +
                      ": expected none, one-euro or one-euro:MIN_CUTOFF_HZ,BETA (e.g. one-euro:0.05,3)");
  };
  if (text.rfind(prefix, 0) != 0) throw bad();
  double min_cutoff = 0, beta = 0;
  char comma = 0, extra = 0;
  if (std::sscanf(text.c_str() + prefix.size(), "%lf%c%lf%c", &min_cutoff, &comma, &beta, &extra) != 3 || comma != ',')
    throw bad();
  s.rotation.min_cutoff_hz = s.position.min_cutoff_hz = min_cutoff;
  s.rotation.beta = s.position.beta = beta;
  try {
    validate_one_euro(s.rotation, "the filter");
  } catch (const InputError& e) {
    throw InputError(option + " " + text + ": " + e.what());
  }
  return s;
}

}  // namespace lumar::tracking
