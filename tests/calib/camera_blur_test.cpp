// estimate_camera_blur against images blurred by a known Gaussian.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/camera_blur.h"

namespace lumar::calib {
namespace {

// Polygons and discs at arbitrary angles, drawn 8 times finer and averaged down (each
// pixel integrates its area, as a sensor's does: a box of variance 1/12 px²), then
// blurred by `sigma` and given a little noise.
cv::Mat scene_blurred_by(double sigma, std::uint64_t seed = 3) {
  const int k = 8;
  cv::Mat fine(480 * k, 640 * k, CV_8UC1, cv::Scalar(60));
  cv::RNG rng(seed);
  for (int i = 0; i < 30; ++i) {
    const cv::Point c(rng.uniform(0, 640 * k), rng.uniform(0, 480 * k));
    const int r = rng.uniform(20 * k, 70 * k);
    if (i % 2)
      cv::circle(fine, c, r, cv::Scalar(rng.uniform(120, 230)), cv::FILLED);
    else
      cv::rectangle(cv::Mat(fine), cv::RotatedRect(c, cv::Size2f(2 * r, r), float(rng.uniform(0, 180))).boundingRect(),
                    cv::Scalar(rng.uniform(0, 50)), cv::FILLED);
  }
  cv::Mat image;
  cv::resize(fine, image, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
  cv::Mat f;
  image.convertTo(f, CV_32F);
  if (sigma > 0) cv::GaussianBlur(f, f, cv::Size(0, 0), sigma);
  cv::Mat noise(f.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.5);
  cv::Mat(f + noise).convertTo(image, CV_8U);
  return image;
}

TEST(CameraBlur, FindsTheGaussianThatBlurredTheImage) {
  for (double sigma : {0.0, 0.6, 1.0, 1.6}) {
    const double expected = std::sqrt(sigma * sigma + 1.0 / 12.0);  // with the pixels' own box
    const CameraBlur blur = estimate_camera_blur(scene_blurred_by(sigma));
    SCOPED_TRACE(sigma);
    EXPECT_NEAR(blur.sigma_px, expected, 0.15 * expected + 0.05) << blur.edges << " edge pixels";
    EXPECT_GT(blur.edges, 1000u);
  }
}

TEST(CameraBlur, MoreBlurIsSeenAsMore) {
  EXPECT_LT(estimate_camera_blur(scene_blurred_by(0.8)).sigma_px + 0.3,
            estimate_camera_blur(scene_blurred_by(1.4)).sigma_px);
}

TEST(CameraBlur, ABlankWallCannotTell) {
  cv::Mat wall(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  EXPECT_THROW(estimate_camera_blur(wall), InputError);
  EXPECT_THROW(estimate_camera_blur(cv::Mat()), InputError);
  EXPECT_THROW(estimate_camera_blur(cv::Mat(10, 10, CV_32FC1, cv::Scalar(0))), InputError);
}

}  // namespace
}  // namespace lumar::calib
