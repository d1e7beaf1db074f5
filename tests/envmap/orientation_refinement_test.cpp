// Rotation refinement of a tracked sweep against the synthetic truth.
#include <gtest/gtest.h>

#include <cmath>

#include "lumar/base/error.h"

#include "lumar/envmap/orientation_refinement.h"
#include "sweep_fixture.h"

namespace lumar {
namespace {

TEST(OrientationRefinement, BringsTrackerNoiseFrom075DegreesToAtMost015) {
  test::SweepSpec spec;  // studio map, 60 brackets of 3 exposures 5 stops apart, 0.75 deg noise
  const test::Sweep& sweep = test::synthetic_sweep(spec);
  const auto& result = test::refined_sweep(spec);
  const double before = test::rms_angle_deg(sweep.tracker, sweep.truth);
  const double after = test::rms_angle_deg(result.rotations, sweep.truth);
  double mean_correction = 0;
  for (double c : result.correction_deg) mean_correction += c / result.correction_deg.size();
  std::printf(
      "tracker %.3f deg RMS -> refined %.3f deg RMS; %d pairs, %d matches, %d unmatched frames; "
      "match residual %.3f -> %.3f deg; mean correction %.3f deg\n",
      before, after, result.pairs, result.matches, result.unmatched_frames, result.residual_before_deg,
      result.residual_after_deg, mean_correction);
  EXPECT_NEAR(before, 0.75, 0.2) << "the fixture's tracker noise";
  EXPECT_LE(after, 0.15);
  EXPECT_EQ(result.unmatched_frames, 0);
  EXPECT_LT(result.residual_after_deg, result.residual_before_deg / 2.5);
  // The gauge: the refined rotations' mean equals the tracker's.
  glm::dvec3 mean(0.0);
  for (std::size_t i = 0; i < sweep.tracker.size(); ++i)
    mean += rotation_log(sweep.tracker[i] * glm::conjugate(result.rotations[i]));
  EXPECT_LT(glm::degrees(glm::length(mean / double(sweep.tracker.size()))), 1e-6);
}

TEST(OrientationRefinement, FramesWithoutFeaturesKeepTheirTrackerRotation) {
  const CameraIntrinsics camera = test::webcam();
  const cv::Mat flat(camera.height, camera.width, CV_8UC3, cv::Scalar::all(128));
  std::vector<calib::FrameFeatures> features(3, calib::extract_frame_features(flat, camera, calib::srgb_response()));
  EXPECT_TRUE(features[0].bearings.empty());
  const std::vector<glm::dquat> tracker = {glm::dquat(1, 0, 0, 0), rotation_exp({0, 0.1, 0}),
                                           rotation_exp({0.1, 0, 0})};
  const auto result = calib::refine_orientations(features, tracker);
  EXPECT_EQ(result.unmatched_frames, 3);
  for (int i = 0; i < 3; ++i) EXPECT_LT(rotation_angle_deg(result.rotations[i], tracker[i]), 1e-9);
  EXPECT_THROW(calib::refine_orientations(features, {glm::dquat(1, 0, 0, 0)}), InputError);
}

}  // namespace
}  // namespace lumar
