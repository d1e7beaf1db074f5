#pragma once
// Decoded tracker samples kept in time order per station, with pose lookup at any
// time between samples: slerp of the rotation (shortest path) and lerp of the
// position between the two samples that bracket t. Euler angles never get here.
// lookup() adds what a render loop needs: a latency offset, a short, bounded
// constant-velocity extrapolation past the newest sample, and a status that says why
// there is no pose when there is none.
#include <cstddef>
#include <map>
#include <optional>
#include <vector>

#include "lumar/base/pose.h"
#include "lumar/base/time.h"
#include "lumar/tracking/pose_sample.h"

namespace lumar::tracking {

// Samples further apart than this are a dropout, not something to interpolate across.
constexpr Nanos kDefaultMaxGap = 200'000'000;  // 200 ms
// How far past the newest sample a pose may be predicted. At 60 Hz a frame is usually
// within 17 ms of a sample; 50 ms covers late records without letting a stalled
// tracker drive the view.
constexpr Nanos kDefaultMaxExtrapolation = 50'000'000;  // 50 ms

enum class PoseStatus {
  Interpolated,  // between two samples (or exactly at one)
  Extrapolated,  // past the newest sample by at most max_extrapolation
  NoSamples,     // nothing from this station yet
  BeforeFirst,   // earlier than the oldest sample
  Gap,           // the samples around t are more than max_gap apart (a dropout)
  TooOld,        // the newest sample is more than max_extrapolation before t
};

const char* to_string(PoseStatus status);

struct PoseLookupSettings {
  // Added to the query time before the lookup: the residual offset between the
  // video clock and tracker times (positive: use later tracker data).
  Nanos time_offset = 0;
  Nanos max_gap = kDefaultMaxGap;
  Nanos max_extrapolation = kDefaultMaxExtrapolation;
};

struct PoseLookup {
  std::optional<Pose> pose;  // set for Interpolated and Extrapolated only
  PoseStatus status = PoseStatus::NoSamples;
  Nanos age = 0;  // query time minus the newest sample's time used (> 0 when extrapolating)
};

class PoseStream {
 public:
  // Inserts in time order (appending is O(1); late samples are placed where they
  // belong). A sample with the same time as an existing one goes after it.
  void add(const PoseSample& sample);

  // Pose of `station` at time t. Exact at sample times; nullopt when t is outside
  // [first, last] sample time of that station, or when the samples bracketing t are
  // more than max_gap apart.
  std::optional<Pose> at(Nanos t, int station = 1, Nanos max_gap = kDefaultMaxGap) const;

  // Pose of `station` at t + settings.time_offset. Inside the samples: as at(). After
  // the newest sample by at most max_extrapolation: constant linear and angular
  // velocity from the two newest samples (if they are at most max_gap apart; a lone
  // sample is held). Otherwise no pose and a status saying why.
  PoseLookup lookup(Nanos t, int station = 1, const PoseLookupSettings& settings = {}) const;

  // Number of samples over all stations.
  std::size_t size() const;
  // Samples of one station in time order (empty if none).
  const std::vector<PoseSample>& samples(int station = 1) const;
  // Stations that have samples, ascending.
  std::vector<int> stations() const;

 private:
  std::map<int, std::vector<PoseSample>> by_station_;
};

}  // namespace lumar::tracking
