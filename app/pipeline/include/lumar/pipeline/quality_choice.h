#pragma once
// `--quality auto` (docs/results.md, "Quality knobs"): the cheapest knobs whose composite
// stays within an error budget of full quality's, chosen on a few frames of the run's own
// video before it starts.
//
// No truth is at hand in a run, so the full-quality composite takes its place in the
// composite-error measure (composite_error.h): every cheaper setting is measured against
// it over the same object, edge and shadow regions. That measure is a mean absolute
// difference, so a setting within b % of full quality is at most about b points worse
// than full quality against any truth; bench_frame_budget checks the choice against one.
//
// The search is greedy, from full quality, one knob at a time in the order of what each
// may save: shading per vertex; half, then a quarter of the shadow lines; 6, then 2 exact
// lights; shadow maps of 64, then 32 texels; coverage meshes within 2, then 4 px. A step is
// kept when its three differences are within the budget and its frames are faster than the
// best so far by kQualityMinGain; a knob's next level is not tried once one is outside the
// budget.
#include <string>
#include <vector>

#include "lumar/pipeline/composite_error.h"
#include "lumar/pipeline/overlay.h"

namespace lumar::pipeline {

struct QualityBudget {
  // Each region's mean |difference| from full quality, in percent of full quality's mean
  // there. The default is about what two takes of one camera differ by: the noise floor of
  // the synthetic recordings' truth lies between 0.5 and 1.9 % (docs/ground_truth.md).
  double percent = 1.5;
  int frames = 6;  // composited per trial, spread over the recording, after one untimed frame
};

// A step must be at least this much faster than the best so far: the clock varies by a few
// percent from one trial to the next.
inline constexpr double kQualityMinGain = 0.05;

struct QualityTrial {
  OverlayQuality quality;
  double ms_per_frame = 0;    // the composite stage, median over the timed frames (robust to a stray pause)
  CompositeError difference;  // against full quality: object_err, edge_err, shadow_err
  bool kept = false;
};

struct QualityChoice {
  QualityBudget budget;
  std::vector<QualityTrial> trials;  // trials[0]: full quality, the reference
  std::size_t chosen = 0;            // index into trials
  const QualityTrial& full() const { return trials.front(); }
  const QualityTrial& choice() const { return trials[chosen]; }
  // "vertex, 4 lines, ...: 27.2 ms/frame against full quality's 78.0 (0.35x), within 1.50 %
  // of it (object 0.32 %, edge 0.72 %, shadow 0.27 %), from 9 trials"
  std::string describe() const;
};

struct ProbeFrame {
  capture::Frame frame;
  Pose T_world_camera;
  // The camera over the frame's shutter (Overlay::shutter_cameras), so that the trials
  // pay for the motion blur as the run will; empty without it.
  std::vector<std::optional<Pose>> shutter_cameras;
};

// Tries settings on `frames` (at least two) from the overlay's current quality, its full
// quality, and leaves the overlay at the choice with its stage times and first-composite
// time cleared (Overlay::reset_times), so that a run's figures start after it. The camera
// noise added to rendered pixels is off while it measures, so that only the knobs differ.
// Each trial is logged; InputError for fewer than two frames.
QualityChoice choose_quality(Overlay& overlay, const std::vector<ProbeFrame>& frames, const QualityBudget& budget);

}  // namespace lumar::pipeline
