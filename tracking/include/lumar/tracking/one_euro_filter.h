#pragma once
// The One Euro filter (Casiez, Roussel, Vogel, CHI 2012) for tracker poses: a first-
// order low-pass whose cutoff rises with speed, so a still camera is smoothed hard
// (little jitter) and a moving one lightly (little lag).
//
//   a(fc, dt) = r / (1 + r), r = 2 pi fc dt
//   v         = low-pass of (x - x_hat_prev) / dt with cutoff d_cutoff
//   fc        = min_cutoff + beta * |v|
//   x_hat     = x_hat_prev + a(fc, dt) (x - x_hat_prev)
//
// Position: x is the translation in metres, v in m/s, beta in Hz per m/s. Rotation:
// v is the angular velocity in rad/s (the rotation vector from the previous output to
// the new sample over dt), beta in Hz per rad/s, and the update is a slerp from the
// previous output toward the sample by a, on the shortest path; never Euler angles.
// The velocity is low-passed as a vector and only then its norm taken, so noise at
// rest averages out instead of raising the cutoff of a still camera.
// With beta = 0 both are plain exponential smoothing with cutoff min_cutoff.
#include <map>
#include <optional>
#include <string>

#include "lumar/base/pose.h"
#include "lumar/base/time.h"
#include "lumar/tracking/pose_sample.h"

namespace lumar::tracking {

struct OneEuroSettings {
  double min_cutoff_hz = 1.0;  // cutoff at rest: lower = less jitter, more lag
  double beta = 0.0;           // cutoff increase per unit of speed (Hz per m/s or per rad/s)
  double d_cutoff_hz = 1.0;    // cutoff of the speed estimate
};

// Throws InputError naming `what` unless the cutoffs are finite and > 0 and beta is
// finite and >= 0.
void validate_one_euro(const OneEuroSettings& settings, const char* what);

// Defaults: the setting bench_tracker_filter chose for an ISOTRAK II (0.75 deg RMS at
// 60 Hz) seen at 640x480: rotation jitter at rest 0.75 -> 0.097 deg RMS (7.1 -> 0.9 px),
// for 33 ms of lag at a steady 30 deg/s turn and about 100 ms while a turn starts.
// Position uses the same numbers (2.5 mm -> 0.3 mm RMS at rest).
struct PoseFilterSettings {
  OneEuroSettings position{0.05, 3.0, 0.1};  // beta in Hz per m/s
  OneEuroSettings rotation{0.05, 3.0, 0.1};  // beta in Hz per rad/s
};

// Filters one station's poses. The first pose passes through unchanged; a pose whose
// time is not after the previous one returns the previous output unchanged.
class OneEuroPoseFilter {
 public:
  explicit OneEuroPoseFilter(PoseFilterSettings settings = {});

  Pose filter(const Pose& pose, Nanos time);
  void reset() { state_.reset(); }
  const PoseFilterSettings& settings() const { return settings_; }

 private:
  struct State {
    Nanos time = 0;
    Pose out;
    glm::dvec3 velocity{0.0};          // filtered, m/s
    glm::dvec3 angular_velocity{0.0};  // filtered, rad/s (transmitter frame)
  };
  PoseFilterSettings settings_;
  std::optional<State> state_;
};

// One OneEuroPoseFilter per station, for a stream of samples from several stations.
class PoseSampleFilter {
 public:
  explicit PoseSampleFilter(PoseFilterSettings settings = {}) : settings_(settings) {
    validate_one_euro(settings.position, "position filter");
    validate_one_euro(settings.rotation, "rotation filter");
  }
  PoseSample filter(PoseSample sample);

 private:
  PoseFilterSettings settings_;
  std::map<int, OneEuroPoseFilter> by_station_;
};

// The pose filter as the command line names it: "none" (nullopt), "one-euro" (the
// defaults above), or "one-euro:MIN_CUTOFF_HZ,BETA" (both for rotation and position).
// InputError naming `option` for anything else.
std::optional<PoseFilterSettings> parse_pose_filter(const std::string& text, const std::string& option = "--filter");

}  // namespace lumar::tracking
