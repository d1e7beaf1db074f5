// Vignetting fit on a synthetic flat field with known fall-off, noise, outliers and the
// 8-bit sRGB round trip of a real video; correction must flatten it.
#include "lumar/calib/vignetting.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/calib/camera_response.h"

namespace lumar::calib {
namespace {

constexpr double kA = -0.3, kB = 0.05, kCx = 331.5, kCy = 228.0, kLevel = 0.55;

// The recordings' model, written out independently of the library.
double true_gain(int x, int y, cv::Size size) {
  const double half_diagonal = 0.5 * std::sqrt(double(size.width) * size.width + double(size.height) * size.height);
  const double r = std::sqrt((x - kCx) * (x - kCx) + (y - kCy) * (y - kCy)) / half_diagonal;
  return 1.0 + kA * r * r + kB * r * r * r * r;
}

struct FlatField {
  cv::Mat video;  // CV_8UC3
  cv::Mat clean;  // CV_8UC1, 255 away from the dust specks
};

// A 640x480 flat field as an 8-bit sRGB video frame: 1 % noise, a few dust specks.
FlatField flat_field_video() {
  const cv::Size size(640, 480);
  cv::RNG rng(7);
  cv::Mat image(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double linear = kLevel * true_gain(x, y, size) * (1.0 + rng.gaussian(0.01));
        image.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uchar>(std::lround(255.0 * linear_to_srgb(float(linear))));
      }
  cv::Mat clean(size, CV_8UC1, cv::Scalar(255));
  for (int i = 0; i < 40; ++i) {
    const cv::Point centre(rng.uniform(0, size.width), rng.uniform(0, size.height));
    cv::circle(image, centre, 4, cv::Scalar(20, 20, 20), cv::FILLED);
    cv::circle(clean, centre, 4 + 8, cv::Scalar(0), cv::FILLED);  // + the blur radius below
  }
  return {image, clean};
}

TEST(Vignetting, RecoversFallOffFromNoisyFlatField) {
  const FlatField field = flat_field_video();
  const cv::Mat linear = linearize(field.video, srgb_response());
  const VignettingFit fit = estimate_vignetting(linear, kCx, kCy);
  std::printf("[ vignetting ] a = %.4f (true %.2f), b = %.4f (true %.2f), level %.4f, residual %.3f %%, %d/%d blocks\n",
              fit.a, kA, fit.b, kB, fit.level, 100 * fit.residual_rms, fit.inliers, fit.samples);
  EXPECT_NEAR(fit.a, kA, 0.01);
  EXPECT_NEAR(fit.b, kB, 0.01);
  EXPECT_NEAR(fit.level, kLevel, 0.01 * kLevel);
  EXPECT_LT(fit.inliers, fit.samples) << "the dust specks should be rejected";

  // Correction flattens the field: relative std of the corrected image, after a small
  // blur that averages the per-pixel noise but not the fall-off.
  const cv::Mat corrected = correct_vignetting(linear, fit.a, fit.b, kCx, kCy);
  const cv::Mat uncorrected_grey = [&] {
    cv::Mat g;
    cv::cvtColor(linear, g, cv::COLOR_BGR2GRAY);
    return g;
  }();
  cv::Mat grey, smooth;
  cv::cvtColor(corrected, grey, cv::COLOR_BGR2GRAY);
  cv::blur(grey, smooth, cv::Size(15, 15));
  const cv::Mat& mask = field.clean;
  cv::Scalar mean, stddev;
  cv::meanStdDev(smooth, mean, stddev, mask);
  cv::Scalar raw_mean, raw_stddev;
  cv::meanStdDev(uncorrected_grey, raw_mean, raw_stddev);
  std::printf("[ vignetting ] relative std before %.2f %%, after correction %.3f %% (%.0f %% of pixels)\n",
              100 * raw_stddev[0] / raw_mean[0], 100 * stddev[0] / mean[0],
              100.0 * cv::countNonZero(mask) / mask.total());
  EXPECT_GT(cv::countNonZero(mask), int(0.9 * mask.total()));
  EXPECT_LT(stddev[0] / mean[0], 0.01);
  EXPECT_GT(raw_stddev[0] / raw_mean[0], 0.05) << "the synthetic field should be visibly vignetted";
}

TEST(Vignetting, GainAndCorrectionMatchTheModel) {
  const cv::Size size(640, 480);
  const cv::Mat gain = vignetting_gain(size, kA, kB, kCx, kCy);
  for (cv::Point p : {cv::Point(0, 0), cv::Point(639, 479), cv::Point(331, 228), cv::Point(100, 400)})
    EXPECT_NEAR(gain.at<float>(p), true_gain(p.x, p.y, size), 1e-6) << p;
  cv::Mat field(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) field.at<float>(y, x) = float(2.0 * true_gain(x, y, size));
  const cv::Mat flat = correct_vignetting(field, kA, kB, kCx, kCy);
  double lo, hi;
  cv::minMaxLoc(flat, &lo, &hi);
  EXPECT_NEAR(lo, 2.0, 1e-5);
  EXPECT_NEAR(hi, 2.0, 1e-5);
  const VignettingFit exact = estimate_vignetting(field, kCx, kCy);
  EXPECT_NEAR(exact.a, kA, 1e-4);
  EXPECT_NEAR(exact.b, kB, 1e-4);
}

TEST(Vignetting, BadInputIsInputError) {
  EXPECT_THROW(estimate_vignetting(cv::Mat(), 1, 1), InputError);
  EXPECT_THROW(estimate_vignetting(cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(100)), 320, 240), InputError);
  EXPECT_THROW(estimate_vignetting(cv::Mat(480, 640, CV_32FC1, cv::Scalar(1)), 700, 240), InputError);
  EXPECT_THROW(correct_vignetting(cv::Mat(480, 640, CV_8UC1), 0, 0, 320, 240), InputError);
}

}  // namespace
}  // namespace lumar::calib
