#include "lumar/tracking/trajectory.h"

#include <cmath>
#include <map>
#include <memory>
#include <numbers>

#include "lumar/base/csv.h"
#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/tracking/pose_stream.h"

namespace lumar::tracking {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

glm::dvec3 station_base(int station) { return {0.30, 0.10 * (station - 1), -0.10}; }
double station_delay_s(int station) { return 0.5 * (station - 1); }

Pose still(int station, Nanos) {
  Pose p;
  p.rotation = polhemus_attitude_to_quat(30.0, 10.0, -5.0);
  p.translation = station_base(station);
  return p;
}

Pose sweep(int station, Nanos t) {
  const double s = nanos_to_seconds(t) - station_delay_s(station);
  Pose p;
  p.rotation = polhemus_attitude_to_quat(60.0 * std::sin(kTwoPi * 0.2 * s), 15.0 * std::sin(kTwoPi * 0.13 * s),
                                         10.0 * std::sin(kTwoPi * 0.07 * s));
  p.translation = station_base(station) + 0.05 * glm::dvec3(std::cos(kTwoPi * 0.1 * s), std::sin(kTwoPi * 0.1 * s),
                                                            0.4 * std::sin(kTwoPi * 0.05 * s));
  return p;
}

Pose spin(int station, Nanos t) {
  const double s = nanos_to_seconds(t) - station_delay_s(station);
  const double azimuth = std::remainder(36.0 * s, 360.0);
  Pose p;
  p.rotation = polhemus_attitude_to_quat(azimuth, 20.0, 0.0);
  p.translation = station_base(station);
  return p;
}

}  // namespace

const std::vector<std::string>& builtin_trajectory_names() {
  static const std::vector<std::string> names{"still", "sweep", "spin"};
  return names;
}

Trajectory builtin_trajectory(const std::string& name) {
  if (name == "still") return still;
  if (name == "sweep") return sweep;
  if (name == "spin") return spin;
  throw InputError("trajectory \"" + name + "\" is not built in; use still, sweep, spin or a CSV file");
}

Trajectory load_trajectory_csv(const std::filesystem::path& path) {
  const std::string where = path.string();
  auto stream = std::make_shared<PoseStream>();
  std::map<int, Nanos> last_time;
  csv::for_each_row(path, read_input_file(path, "trajectory"),
                    {{"time_ns", "station", "x", "y", "z", "qw", "qx", "qy", "qz"}}, csv::LastLine::kRead,
                    [&](const csv::Row& row) {
                      PoseSample s;
                      s.time = row.integer("time_ns");
                      s.station = row.small_integer("station");
                      if (s.station < 1 || s.station > 9)
                        row.fail("station " + std::to_string(s.station) + " is outside 1..9");
                      const glm::dquat q(row.real("qw"), row.real("qx"), row.real("qy"), row.real("qz"));
                      const double norm = glm::length(q);
                      if (std::abs(norm - 1.0) > 0.01) row.fail("the quaternion is not unit length");
                      if (auto it = last_time.find(s.station); it != last_time.end() && s.time < it->second)
                        row.fail("time goes backwards for station " + std::to_string(s.station));
                      last_time[s.station] = s.time;
                      s.T_transmitter_sensor.translation = {row.real("x"), row.real("y"), row.real("z")};
                      s.T_transmitter_sensor.rotation = q / norm;
                      stream->add(s);
                    });
  if (stream->size() == 0) throw InputError(where + ": no poses; the trajectory needs at least one row");
  const int fallback = stream->stations().front();
  return [stream, fallback](int station, Nanos t) {
    const auto& samples = stream->samples(station).empty() ? stream->samples(fallback) : stream->samples(station);
    const Nanos first = samples.front().time, last = samples.back().time;
    if (last == first) return samples.front().T_transmitter_sensor;
    const Nanos period = last - first;
    const Nanos into = ((t % period) + period) % period;
    const int st = samples.front().station;
    // max_gap = the whole span: the CSV's rows define the motion, however sparse.
    return stream->at(first + into, st, period).value_or(samples.front().T_transmitter_sensor);
  };
}

}  // namespace lumar::tracking
