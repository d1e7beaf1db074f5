#include "lumar/calib/latency_estimation.h"

#include <algorithm>
#include <cmath>

#include "lumar/base/error.h"

namespace lumar::calib {

std::vector<AngularSpeedSample> angular_speed(const std::vector<Nanos>& times, const std::vector<glm::dquat>& rotations,
                                              Nanos span) {
  std::vector<AngularSpeedSample> out;
  const std::size_t n = std::min(times.size(), rotations.size());
  std::size_t a = 0, b = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (a < i && times[a] < times[i] - span / 2) ++a;
    if (b < i) b = i;
    while (b + 1 < n && times[b + 1] <= times[i] + span / 2) ++b;
    const Nanos dt = times[b] - times[a];
    if (dt < span / 2 || dt <= 0) continue;
    out.push_back({times[a] + dt / 2, rotation_angle_deg(rotations[a], rotations[b]) / nanos_to_seconds(dt)});
  }
  return out;
}

namespace {

// Linear interpolation of the speed at t; false outside the series or across a gap.
bool speed_at(const std::vector<AngularSpeedSample>& s, Nanos t, Nanos max_gap, double& v) {
  if (s.empty() || t < s.front().time || t > s.back().time) return false;
  const auto it =
      std::lower_bound(s.begin(), s.end(), t, [](const AngularSpeedSample& a, Nanos x) { return a.time < x; });
  if (it->time == t) {
    v = it->speed_deg_s;
    return true;
  }
  const auto prev = it - 1;
  if (it->time - prev->time > max_gap) return false;
  const double u = double(t - prev->time) / double(it->time - prev->time);
  v = prev->speed_deg_s + u * (it->speed_deg_s - prev->speed_deg_s);
  return true;
}

Nanos typical_spacing(const std::vector<AngularSpeedSample>& s) {
  std::vector<Nanos> d;
  for (std::size_t i = 1; i < s.size(); ++i) d.push_back(s[i].time - s[i - 1].time);
  if (d.empty()) return 0;
  std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(d.size() / 2), d.end());
  return d[d.size() / 2];
}

}  // namespace

TimeOffsetEstimate estimate_time_offset(const std::vector<AngularSpeedSample>& video,
                                        const std::vector<AngularSpeedSample>& tracker,
                                        const TimeOffsetOptions& options) {
  if (options.step <= 0 || options.max_offset < 0)
    throw InputError("time offset search: step must be positive and the range not negative");
  // Each tracker sample is compared with the video's speed interpolated at its time: the
  // video's is the precise one, and interpolating the noisy series instead would average
  // its noise more at some offsets than at others, biasing the peak towards them.
  const Nanos max_gap = 3 * std::max<Nanos>(typical_spacing(video), 1);
  const int steps = int(options.max_offset / options.step);
  TimeOffsetEstimate out;
  out.curve.assign(std::size_t(2 * steps + 1), -2.0);
  int best = -1;
  std::vector<double> x, y;
  int min_samples = 1 << 30;
  for (int k = -steps; k <= steps; ++k) {
    const Nanos offset = Nanos(k) * options.step;
    x.clear(), y.clear();
    for (const auto& tr : tracker) {
      double s;
      if (speed_at(video, tr.time - offset, max_gap, s)) x.push_back(s), y.push_back(tr.speed_deg_s);
    }
    min_samples = std::min(min_samples, int(x.size()));
    if (x.size() < 10) continue;
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
    mx /= double(x.size()), my /= double(x.size());
    double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx), syy += (y[i] - my) * (y[i] - my);
    if (!(sxx > 0 && syy > 0)) continue;
    const double r = sxy / std::sqrt(sxx * syy);
    out.curve[std::size_t(k + steps)] = r;
    if (best < 0 || r > out.curve[std::size_t(best)]) best = k + steps, out.samples = int(x.size());
  }
  if (best < 0)
    throw InputError(min_samples < 10
                         ? "time offset: the video and the tracker overlap too little to compare their motion"
                         : "time offset: the angular speed is constant, nothing to correlate; turn the camera "
                           "at varying speed while filming the board");
  out.peak_correlation = out.curve[std::size_t(best)];
  out.correlation_at_zero = out.curve[std::size_t(steps)];
  double refined = best - steps;
  if (best > 0 && best < 2 * steps && out.curve[std::size_t(best - 1)] > -2 && out.curve[std::size_t(best + 1)] > -2) {
    const double l = out.curve[std::size_t(best - 1)], c = out.curve[std::size_t(best)],
                 r = out.curve[std::size_t(best + 1)];
    const double denom = l - 2 * c + r;
    if (denom < 0) refined += std::clamp(0.5 * (l - r) / denom, -0.5, 0.5);
  }
  out.offset = Nanos(std::llround(refined * double(options.step)));
  return out;
}

}  // namespace lumar::calib
