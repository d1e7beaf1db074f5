// The composite-error measure (lumar/pipeline/composite_error.h) on images made by hand:
// its regions' widths, an error of known size in each region, and a known noise ratio.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "lumar/pipeline/composite_error.h"

namespace lumar::pipeline {
namespace {

const cv::Size kSize(200, 160);
const cv::Point kCentre(70, 80);
constexpr int kRadius = 30;

cv::Mat disc_mask() {
  cv::Mat mask = cv::Mat::zeros(kSize, CV_8UC1);
  cv::circle(mask, kCentre, kRadius, 255, cv::FILLED);
  return mask;
}

// The room at 8-bit `room`, the object at `object`.
cv::Mat frame(int room, int object) {
  cv::Mat image(kSize, CV_8UC3, cv::Scalar::all(room));
  image.setTo(cv::Scalar::all(object), disc_mask());
  return image;
}

TEST(CompositeError, RegionsAreTheErodedMaskABandAndTheChangedRoom) {
  // A square object (x and y from 40 to 100), so that distances are plain.
  const CompositeErrorMeter meter(calib::srgb_response(1.0));
  cv::Mat mask = cv::Mat::zeros(kSize, CV_8UC1);
  mask(cv::Rect(40, 40, 61, 61)).setTo(255);
  cv::Mat truth(kSize, CV_8UC3, cv::Scalar::all(100)), empty = truth.clone();
  truth.setTo(cv::Scalar::all(160), mask);
  empty.setTo(cv::Scalar::all(120), mask);
  cv::rectangle(truth, cv::Rect(150, 60, 30, 40), cv::Scalar::all(80), cv::FILLED);  // a shadow
  const CompositeRegions r = composite_regions(mask, meter.linear(truth), meter.linear(empty));
  // Object: from 2 px in; edge: 1 px out to 2 px in.
  EXPECT_EQ(r.object.at<uchar>(70, 42), 255);
  EXPECT_EQ(r.object.at<uchar>(70, 41), 0);
  for (int x : {39, 40, 41}) EXPECT_EQ(r.edge.at<uchar>(70, x), 255) << x;
  EXPECT_EQ(r.edge.at<uchar>(70, 38), 0);
  EXPECT_EQ(r.edge.at<uchar>(70, 42), 0);
  EXPECT_EQ(cv::countNonZero(r.object), 57 * 57);
  EXPECT_EQ(cv::countNonZero(r.edge), 63 * 63 - 57 * 57);
  // Shadow: exactly where the truth differs from the empty room (these images are not
  // box-filtered, so the rectangle itself), and nowhere on the object.
  EXPECT_EQ(cv::countNonZero(r.shadow), 30 * 40);
  EXPECT_EQ(cv::countNonZero(r.shadow & (r.edge | r.object)), 0);
}

TEST(CompositeError, KnownErrorsInEachRegion) {
  CompositeErrorMeter meter(calib::srgb_response(1.0));
  const cv::Mat mask = disc_mask();
  // The truth: the whole room in the object's shadow (80 where the empty room has 100).
  const cv::Mat empty = frame(100, 160), truth = frame(80, 160);
  // The composite: the object 10 % too bright in linear light, and no shadow at all.
  const auto linear = [&](int v) { return double(calib::srgb_response(1.0)(1, v)); };
  int brighter = 160;
  while (linear(brighter) < 1.1 * linear(160)) ++brighter;
  meter.add(frame(100, brighter), truth, truth, empty, mask);
  const CompositeError e = meter.result();
  // (The object region's rim pixels' 5×5 boxes reach a few room pixels.)
  EXPECT_NEAR(e.object_err, 100.0 * (linear(brighter) / linear(160) - 1.0), 0.2);
  // The missing shadow, but for the few pixels whose 5×5 box reaches the object.
  const double missing = 100.0 * (linear(100) / linear(80) - 1.0);
  EXPECT_LE(e.shadow_err, missing + 1e-3);
  EXPECT_GT(e.shadow_err, 0.97 * missing);
  EXPECT_GT(e.edge_err, 10.0);
  EXPECT_EQ(e.noise_floor_object_err, 0.0);  // the other seed given as the truth itself
  EXPECT_EQ(e.frames, 1);
  // Every room pixel beyond the band is in the shadow.
  const CompositeRegions r = composite_regions(mask, meter.linear(truth), meter.linear(empty));
  EXPECT_EQ(e.pixels[2], kSize.area() - cv::countNonZero(r.object | r.edge));
}

TEST(CompositeError, AnExactCompositeHasNoErrorAndTheTruthsNoise) {
  CompositeErrorMeter meter(calib::srgb_response(1.0));
  const cv::Mat mask = disc_mask();
  cv::Mat truth = frame(100, 160), other = frame(100, 160), composite = frame(100, 160);
  cv::RNG rng(3);
  cv::Mat noise(kSize, CV_16SC3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 2);
  cv::add(truth, noise, truth, cv::noArray(), CV_8UC3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 2);
  cv::add(other, noise, other, cv::noArray(), CV_8UC3);
  // The composite with twice the truth's noise.
  rng.fill(noise, cv::RNG::NORMAL, 0, 4);
  cv::add(composite, noise, composite, cv::noArray(), CV_8UC3);
  meter.add(truth, truth, other, frame(100, 100), mask);
  const CompositeError same = meter.result();
  EXPECT_EQ(same.object_err, 0.0);
  EXPECT_EQ(same.edge_err, 0.0);
  EXPECT_DOUBLE_EQ(same.noise_ratio, 1.0);
  EXPECT_GT(same.noise_floor_object_err, 0.1);  // two seeds' noise, box-filtered
  CompositeErrorMeter noisy(calib::srgb_response(1.0));
  noisy.add(composite, truth, other, frame(100, 100), mask);
  EXPECT_NEAR(noisy.result().noise_ratio, 2.0, 0.15);
  EXPECT_EQ(noisy.result().specks, 0) << "noise makes no specks";
}

TEST(CompositeError, DarkSpecksTheTruthDoesNotHaveAreCounted) {
  const cv::Mat mask = disc_mask();
  const cv::Mat truth = frame(100, 160);
  cv::Mat composite = truth.clone();
  // Three dark pixels inside the object, one where the truth has one too, one on the room.
  for (const cv::Point p : {cv::Point(60, 80), cv::Point(75, 70), cv::Point(80, 95)})
    composite.at<cv::Vec3b>(p) = cv::Vec3b(20, 20, 20);
  cv::Mat truth_with_hole = truth.clone();
  truth_with_hole.at<cv::Vec3b>(cv::Point(80, 95)) = cv::Vec3b(20, 20, 20);
  composite.at<cv::Vec3b>(cv::Point(150, 20)) = cv::Vec3b(5, 5, 5);
  CompositeErrorMeter meter(calib::srgb_response(1.0));
  meter.add(composite, truth_with_hole, truth_with_hole, frame(100, 100), mask);
  EXPECT_EQ(meter.result().specks, 2);
}

}  // namespace
}  // namespace lumar::pipeline
