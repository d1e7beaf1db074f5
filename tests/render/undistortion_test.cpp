// The background pass: video drawn through the undistortion map must match
// calib::undistort_in_linear_light (cv::remap of the light), and the decode-to-linear /
// encode-to-sRGB round trip must be lossless.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/undistortion.h"
#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

// A frame with detail at every scale: blurred checkerboard, colour ramps and noise.
cv::Mat textured_frame(cv::Size size) {
  cv::Mat frame(size, CV_8UC3);
  cv::RNG rng(7);
  for (int r = 0; r < size.height; ++r)
    for (int c = 0; c < size.width; ++c) {
      const bool check = ((c / 24) + (r / 24)) % 2 == 0;
      const int base = check ? 200 : 40;
      frame.at<cv::Vec3b>(r, c) = cv::Vec3b(cv::saturate_cast<uchar>(base + (c % 97) / 3 - 16),
                                            cv::saturate_cast<uchar>(base * (r + 100) / 600 + rng.uniform(0, 20)),
                                            cv::saturate_cast<uchar>(255 * c / size.width));
    }
  cv::GaussianBlur(frame, frame, cv::Size(0, 0), 0.8);
  return frame;
}

TEST(RenderUndistortion, MatchesRemappingTheLight) {
  headless_context();
  CameraIntrinsics camera = make_camera(640, 480, 536.1, 536.0, 342.4, 235.5);
  camera.distortion = {-0.28, 0.09, 0.001, -0.0005, 0.0};
  const cv::Size size(camera.width, camera.height);
  const cv::Mat K(camera.camera_matrix());
  cv::Mat map_x, map_y;
  cv::initUndistortRectifyMap(K, camera.distortion_coefficients(), cv::Mat(), K, size, CV_32FC1, map_x, map_y);

  const cv::Mat frame = textured_frame(size);
  // The renderer's default response is sRGB's.
  const cv::Mat expected = calib::undistort_in_linear_light(frame, {map_x, map_y, camera}, calib::srgb_response(1.0));

  gl::Renderer renderer(camera);
  renderer.set_undistortion_map(map_x, map_y);
  const cv::Mat out = renderer.render_overlay(frame, Pose{}, 1.0);
  ASSERT_EQ(out.type(), CV_8UC3);
  ASSERT_EQ(out.size(), size);

  // Interior: away from the image border and from where the map leaves the frame,
  // where the two border rules may legitimately differ by part of a pixel.
  double sum = 0;
  int count = 0, worst = 0;
  for (int r = 2; r < size.height - 2; ++r)
    for (int c = 2; c < size.width - 2; ++c) {
      const float x = map_x.at<float>(r, c), y = map_y.at<float>(r, c);
      if (x < 1 || y < 1 || x > size.width - 2 || y > size.height - 2) continue;
      for (int k = 0; k < 3; ++k) {
        const int d = std::abs(int(out.at<cv::Vec3b>(r, c)[k]) - int(expected.at<cv::Vec3b>(r, c)[k]));
        sum += d;
        worst = std::max(worst, d);
      }
      ++count;
    }
  const double mean = sum / (3.0 * count);
  std::printf("undistortion vs the light remapped: %d interior pixels, mean |diff| %.4f levels, max %d levels\n", count,
              mean, worst);
  EXPECT_GT(count, size.area() / 2);
  EXPECT_LE(mean, 1.0);
  // The distortion is strong at the corners: the warp must really be applied.
  cv::Mat unwarped_diff;
  cv::absdiff(out, frame, unwarped_diff);
  EXPECT_GT(cv::mean(unwarped_diff)[0], 5.0);
}

TEST(RenderUndistortion, MixesLightNotCodes) {
  // Black and white columns read half a pixel to the right: every pixel is half of each,
  // which in light is sRGB code 188. Mixing the codes, as cv::remap of the frame does,
  // would give 128 and darken every edge between bright and dark.
  headless_context();
  const CameraIntrinsics camera = make_camera(64, 48, 60, 60, 32, 24);
  cv::Mat map_x(camera.height, camera.width, CV_32FC1), map_y(camera.height, camera.width, CV_32FC1);
  for (int r = 0; r < camera.height; ++r)
    for (int c = 0; c < camera.width; ++c) map_x.at<float>(r, c) = float(c) + 0.5f, map_y.at<float>(r, c) = float(r);
  cv::Mat columns(camera.height, camera.width, CV_8UC3);
  for (int c = 0; c < camera.width; ++c) columns.col(c).setTo(cv::Scalar::all(c % 2 ? 255 : 0));
  gl::Renderer renderer(camera);
  renderer.set_undistortion_map(map_x, map_y);
  const cv::Mat out = renderer.render_overlay(columns, Pose{}, 1.0);
  for (int r = 1; r < camera.height - 1; r += 7)
    for (int c = 1; c < camera.width - 2; ++c)
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(out.at<cv::Vec3b>(r, c)[k], 188, 1) << "pixel " << c << ", " << r;
}

TEST(RenderUndistortion, WithoutMapTheVideoRoundTripsExactly) {
  headless_context();
  const CameraIntrinsics camera = make_camera(320, 256, 300, 300, 160, 128);
  // Every 8-bit level in every channel, in different places.
  cv::Mat frame(256, 320, CV_8UC3);
  for (int r = 0; r < frame.rows; ++r)
    for (int c = 0; c < frame.cols; ++c)
      frame.at<cv::Vec3b>(r, c) = cv::Vec3b(uchar(r), uchar((c + r) % 256), uchar((3 * c) % 256));
  gl::Renderer renderer(camera);
  gl::OverlayTimings timings;
  timings.upload_ms = -1;
  const cv::Mat out = renderer.render_overlay(frame, Pose{}, 1.0, &timings);
  // Filled in when asked for (no claim about how fast: that is the benchmark's job).
  EXPECT_GE(timings.upload_ms, 0.0);
  EXPECT_GT(timings.upload_ms + timings.background_ms + timings.depth_ms + timings.objects_ms + timings.readback_ms,
            0.0);
  cv::Mat diff;
  cv::absdiff(out, frame, diff);
  double worst = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
  std::printf("unwarped round trip: max |diff| %.0f levels\n", worst);
  EXPECT_EQ(worst, 0.0);

  // A frame of another size is scaled to the output: a constant frame stays constant.
  const cv::Mat small(100, 80, CV_8UC3, cv::Scalar(17, 128, 250));
  const cv::Mat scaled = renderer.render_overlay(small, Pose{}, 1.0);
  cv::Mat scaled_diff;
  cv::absdiff(scaled, cv::Scalar(17, 128, 250), scaled_diff);
  cv::minMaxLoc(scaled_diff.reshape(1), nullptr, &worst);
  EXPECT_EQ(worst, 0.0);
}

TEST(RenderUndistortion, RejectsMapsOfTheWrongShape) {
  headless_context();
  gl::Renderer renderer(make_camera(64, 48, 50, 50, 32, 24));
  const cv::Mat wrong_size(47, 64, CV_32FC1, cv::Scalar(0));
  EXPECT_THROW(renderer.set_undistortion_map(wrong_size, wrong_size), InputError);
  const cv::Mat wrong_type(48, 64, CV_16SC2, cv::Scalar(0));
  const cv::Mat ok(48, 64, CV_32FC1, cv::Scalar(0));
  EXPECT_THROW(renderer.set_undistortion_map(wrong_type, ok), InputError);
  EXPECT_THROW(renderer.render_overlay(cv::Mat(48, 64, CV_8UC1), Pose{}, 1.0), InputError);
}

}  // namespace
}  // namespace lumar::test
