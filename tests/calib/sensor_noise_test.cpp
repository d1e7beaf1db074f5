// Sensor-noise estimate on synthetic video of a known camera: a smooth scene with flat
// patches, gradients and a fine checkerboard, Gaussian read + shot noise added in linear
// light, then the sRGB curve and 8-bit rounding.
#include "lumar/calib/sensor_noise.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/calib/camera_response.h"

namespace lumar::calib {
namespace {

// The camera: read sigma and per-channel shot gain (variance per unit signal), BGR.
constexpr double kReadSigma = 0.002;
constexpr double kShotGain[3] = {0.0003, 0.0004, 0.0005};

double true_sigma(int channel, double linear, double scale = 1.0) {
  return scale * std::sqrt(kReadSigma * kReadSigma + kShotGain[channel] * linear);
}

// Linear BGR scene, 640x480: per-channel gradients over 0.02..0.8, flat grey and
// coloured rectangles, and a 1-pixel checkerboard (0.25 / 0.45) that no flat patch has.
const cv::Mat& scene() {
  static const cv::Mat s = [] {
    cv::Mat m(480, 640, CV_32FC3);
    for (int y = 0; y < m.rows; ++y)
      for (int x = 0; x < m.cols; ++x) {
        const float u = float(x) / float(m.cols - 1), v = float(y) / float(m.rows - 1);
        m.at<cv::Vec3f>(y, x) = {0.02f + 0.78f * u, 0.02f + 0.78f * v, 0.8f - 0.78f * (u + v) / 2};
      }
    const auto flat = [&](int x, int y, cv::Vec3f bgr) {
      m(cv::Rect(x, y, 120, 100)).setTo(cv::Scalar(bgr[0], bgr[1], bgr[2]));
    };
    flat(30, 30, {0.05f, 0.05f, 0.05f});
    flat(190, 30, {0.18f, 0.18f, 0.18f});
    flat(350, 30, {0.5f, 0.5f, 0.5f});
    flat(30, 200, {0.1f, 0.4f, 0.7f});
    flat(190, 200, {0.7f, 0.25f, 0.03f});
    for (int y = 300; y < 470; ++y)
      for (int x = 330; x < 630; ++x) m.at<cv::Vec3f>(y, x) = cv::Vec3f::all((x + y) % 2 ? 0.45f : 0.25f);
    return m;
  }();
  return s;
}

// Frames of the scene with the camera's noise times `scale`, sRGB-encoded to 8 bits.
std::vector<cv::Mat> frames(double scale, int count = 4, std::uint64_t seed = 11) {
  cv::RNG rng(seed);
  std::vector<cv::Mat> out;
  for (int i = 0; i < count; ++i) {
    cv::Mat f(scene().size(), CV_8UC3);
    for (int y = 0; y < f.rows; ++y)
      for (int x = 0; x < f.cols; ++x)
        for (int c = 0; c < 3; ++c) {
          const double linear = scene().at<cv::Vec3f>(y, x)[c];
          const double noisy = linear + rng.gaussian(true_sigma(c, linear, scale));
          f.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uchar>(std::lround(255.0 * linear_to_srgb(float(noisy))));
        }
    out.push_back(f);
  }
  return out;
}

TEST(SensorNoise, RecoversReadAndShotNoise) {
  const std::vector<cv::Mat> video = frames(1.0);
  const auto start = std::chrono::steady_clock::now();
  const SensorNoise noise = estimate_sensor_noise(video, srgb_response(1.0));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("[ sensor noise ] 4 frames 640x480 in %.1f ms, %zu patches\n", ms, noise.patches);
  for (int c = 0; c < 3; ++c) {
    std::printf("[ sensor noise ] channel %d: read sigma %.5f (true %.5f), shot gain %.6f (true %.6f)\n", c,
                std::sqrt(noise.read_variance[size_t(c)]), kReadSigma, noise.shot_gain[size_t(c)], kShotGain[c]);
    for (double linear : {0.05, 0.18, 0.5}) {
      const double truth = true_sigma(c, linear);
      std::printf("[ sensor noise ]   sigma at %.2f: %.5f (true %.5f, %+.1f %%)\n", linear, noise.sigma(c, linear),
                  truth, 100 * (noise.sigma(c, linear) / truth - 1));
      EXPECT_NEAR(noise.sigma(c, linear), truth, 0.15 * truth) << "channel " << c << " at " << linear;
    }
  }
  EXPECT_GT(noise.patches, 1000u);
}

TEST(SensorNoise, NoiseFreeFramesReadNearZero) {
  const CameraResponse response = srgb_response(1.0);
  const SensorNoise clean = estimate_sensor_noise(frames(0.0), response);
  const SensorNoise noisy = estimate_sensor_noise(frames(1.0), response);
  for (int c = 0; c < 3; ++c) {
    std::printf("[ sensor noise ] channel %d sigma at 0.18: noise-free %.6f, noisy %.5f\n", c, clean.sigma(c, 0.18),
                noisy.sigma(c, 0.18));
    EXPECT_LT(clean.sigma(c, 0.18), 0.1 * noisy.sigma(c, 0.18)) << "channel " << c;
  }
}

TEST(SensorNoise, TwiceTheNoiseTwiceTheSigma) {
  const CameraResponse response = srgb_response(1.0);
  const SensorNoise once = estimate_sensor_noise(frames(1.0), response);
  const SensorNoise twice = estimate_sensor_noise(frames(2.0, 4, 12), response);
  for (int c = 0; c < 3; ++c)
    for (double linear : {0.05, 0.18, 0.5}) {
      const double ratio = twice.sigma(c, linear) / once.sigma(c, linear);
      std::printf("[ sensor noise ] channel %d at %.2f: twice / once = %.3f\n", c, linear, ratio);
      EXPECT_GT(ratio, 1.7) << "channel " << c << " at " << linear;
      EXPECT_LT(ratio, 2.3) << "channel " << c << " at " << linear;
    }
}

TEST(SensorNoise, RejectsBadInput) {
  const CameraResponse response = srgb_response(1.0);
  EXPECT_THROW(estimate_sensor_noise({}, response), InputError);
  EXPECT_THROW(estimate_sensor_noise({cv::Mat(480, 640, CV_8UC1, cv::Scalar(100))}, response), InputError);
  try {
    estimate_sensor_noise({cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(255))}, response);
    ADD_FAILURE() << "a clipped frame gave an estimate";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("only 0 unclipped"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lumar::calib
