// decode_jpeg: libjpeg's pixels, as OpenCV's imdecode gives them, with its warnings
// counted instead of printed, and no image from bytes that are not a JPEG.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <random>
#include <vector>

#include "lumar/capture/jpeg_decoder.h"
#include "recording_test_support.h"

namespace lumar::capture {
namespace {

std::vector<std::uint8_t> encode(const cv::Mat& image, int quality = 95) {
  std::vector<std::uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, quality}));
  return bytes;
}

cv::Mat noisy(cv::Size size, std::int64_t seed) { return test::noisy_numbered_image(seed, size, 6); }

TEST(JpegDecoder, GivesImdecodesPixels) {
  const cv::Mat image = noisy({320, 240}, 3);
  const std::vector<std::uint8_t> bytes = encode(image);
  const DecodedJpeg d = decode_jpeg(bytes);
  ASSERT_EQ(d.bgr.type(), CV_8UC3);
  ASSERT_EQ(d.bgr.size(), image.size());
  EXPECT_EQ(d.warnings, 0);
  EXPECT_EQ(cv::norm(d.bgr, cv::imdecode(bytes, cv::IMREAD_COLOR), cv::NORM_INF), 0.0);
  EXPECT_LT(test::mean_abs_diff(d.bgr, image), 6.0);  // the codec's loss, not another image
}

TEST(JpegDecoder, SpreadsAGreyImageToThreeChannels) {
  cv::Mat grey(120, 160, CV_8UC1);
  cv::randu(grey, 0, 256);
  const std::vector<std::uint8_t> bytes = encode(grey);
  const DecodedJpeg d = decode_jpeg(bytes);
  ASSERT_EQ(d.bgr.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(d.bgr, cv::imdecode(bytes, cv::IMREAD_COLOR), cv::NORM_INF), 0.0);
}

// OpenCV 4.6's MJPEG writer drops the last 4 bytes of some frames (opencv#24171): the
// frame still decodes, nearly whole, and the warning is counted, not written to stderr.
TEST(JpegDecoder, AFrameCutShortDecodesQuietlyWithAWarning) {
  const cv::Mat image = noisy({320, 240}, 5);
  std::vector<std::uint8_t> bytes = encode(image);
  bytes.resize(bytes.size() - 4);
  testing::internal::CaptureStderr();
  const DecodedJpeg d = decode_jpeg(bytes);
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "");
  ASSERT_FALSE(d.bgr.empty());
  EXPECT_GE(d.warnings, 1);
  EXPECT_LT(test::mean_abs_diff(d.bgr, image), 6.0);
}

TEST(JpegDecoder, BytesThatAreNoJpegGiveNoImage) {
  std::vector<std::uint8_t> garbage(5000);
  std::mt19937 rng(7);
  for (auto& b : garbage) b = std::uint8_t(rng());
  const std::vector<std::uint8_t> jpeg = encode(noisy({64, 48}, 1));
  testing::internal::CaptureStderr();
  EXPECT_TRUE(decode_jpeg(garbage).bgr.empty());
  EXPECT_TRUE(decode_jpeg({}).bgr.empty());
  EXPECT_TRUE(decode_jpeg(std::span(jpeg).first(20)).bgr.empty());  // the header cut off
  garbage[0] = 0xFF, garbage[1] = 0xD8;                             // a start marker, then noise
  EXPECT_TRUE(decode_jpeg(garbage).bgr.empty());
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace lumar::capture
