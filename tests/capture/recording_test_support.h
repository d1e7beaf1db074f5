#pragma once
// Deterministic test data for recordings: frames that carry their index in their
// pixels, tracker chunks and poses that can be regenerated from their number.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "lumar/base/error.h"
#include "lumar/base/pose.h"
#include "lumar/tracking/byte_chunk.h"
#include "lumar/tracking/pose_sample.h"

namespace lumar::test {

// Removes a scratch directory when the test passed; keeps it for inspection if not.
struct RemoveOnSuccess {
  std::filesystem::path dir;
  ~RemoveOnSuccess() {
    std::error_code ec;
    if (!testing::Test::HasFailure()) std::filesystem::remove_all(dir, ec);
  }
};

// DIR/session.json as the writer left it, every key (the reader parses only the session's own).
inline nlohmann::json session_file(const std::filesystem::path& dir) {
  std::ifstream in(dir / "session.json");
  return nlohmann::json::parse(in);
}

// A gradient, a block whose colour changes a lot from one index to the next, and
// the index written large, so a frame decoded out of order cannot pass for another.
inline cv::Mat numbered_image(std::int64_t i, cv::Size size) {
  cv::Mat img(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(std::uint8_t(x * 255 / size.width), std::uint8_t(y * 255 / size.height),
                                          std::uint8_t((i * 37) % 256));
  const cv::Rect block(size.width / 4, size.height / 4, size.width / 2, size.height / 2);
  cv::rectangle(img, block,
                cv::Scalar(double((i * 53) % 256), double((i * 101 + 50) % 256), double((i * 151 + 100) % 256)),
                cv::FILLED);
  cv::putText(img, std::to_string(i), {block.x + 4, block.y + block.height - 8}, cv::FONT_HERSHEY_SIMPLEX,
              size.height / 80.0, cv::Scalar(255, 255, 255), std::max(1, size.height / 60));
  return img;
}

// numbered_image, blurred by a Gaussian of `blur_px` (0: none), with Gaussian noise of
// `sigma` levels seeded by i: a camera's frame rather than flat blocks, for lossy codecs.
inline cv::Mat noisy_numbered_image(std::int64_t i, cv::Size size, double sigma, double blur_px = 0) {
  cv::Mat image = numbered_image(i, size), noise(size, CV_16SC3), out;
  if (blur_px > 0) cv::GaussianBlur(image, image, {0, 0}, blur_px);
  cv::theRNG().state = std::uint64_t(i) + 1;
  cv::randn(noise, 0, sigma);
  cv::add(image, noise, out, cv::noArray(), CV_8UC3);
  return out;
}

// Mean absolute difference per channel, in 8-bit levels.
inline double mean_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  return cv::norm(a, b, cv::NORM_L1) / double(a.total() * a.channels());
}

inline constexpr Nanos kFramePeriod = 33'333'333;

inline tracking::ByteChunk numbered_chunk(int i) {
  tracking::ByteChunk c;
  c.arrival = i == 1 ? -12'345 : Nanos(i) * 1'000'003 + 5;  // negative: before the first frame
  const int size = (i * 37) % 61;                           // chunk 0 is empty
  for (int k = 0; k < size; ++k) c.bytes.push_back(std::uint8_t((i * 13 + k * 7) & 0xFF));
  return c;
}

// Full-precision doubles, so a lossy text round trip would show.
inline Pose numbered_pose(int i) {
  std::mt19937_64 rng(std::uint64_t(i) * 7919 + 1);
  std::uniform_real_distribution<double> u(-3, 3);
  std::normal_distribution<double> n;
  Pose p;
  p.translation = {u(rng), u(rng), u(rng)};
  if (i == 0) p.translation = {0.1, -1e-300, 123456789.123456789};
  p.rotation = glm::normalize(glm::dquat(n(rng), n(rng), n(rng), n(rng)));
  return p;
}

inline tracking::PoseSample numbered_sample(int i) { return {Nanos(i) * 8'333'333 + 3, 1 + i % 2, numbered_pose(i)}; }

inline void expect_same_pose(const Pose& a, const Pose& b) {
  EXPECT_EQ(a.translation.x, b.translation.x);
  EXPECT_EQ(a.translation.y, b.translation.y);
  EXPECT_EQ(a.translation.z, b.translation.z);
  EXPECT_EQ(a.rotation.w, b.rotation.w);
  EXPECT_EQ(a.rotation.x, b.rotation.x);
  EXPECT_EQ(a.rotation.y, b.rotation.y);
  EXPECT_EQ(a.rotation.z, b.rotation.z);
}

// The message of the InputError that `fn` throws; a test failure if it throws
// nothing or something else.
template <class F>
std::string input_error_message(F&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return {};
}

}  // namespace lumar::test
