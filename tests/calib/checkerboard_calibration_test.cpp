// Checkerboard calibration on the 13 real webcam photographs, the bundled calibration
// file made from them, and the error cases.
#include "lumar/calib/checkerboard_calibration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "test_paths.h"

namespace lumar::calib {
namespace {

using test::Scratch;

// Calibrated once per test run; several tests look at the same result.
const CalibrationResult& shared_result() {
  static const CalibrationResult result = calibrate_checkerboard(test::checkerboard_images(), {9, 6}, 0.025);
  return result;
}

void expect_input_error(const std::function<void()>& call, const std::string& needle) {
  try {
    call();
    FAIL() << "no InputError; expected one mentioning " << needle;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

TEST(CheckerboardCalibration, RealImagesGiveTheKnownErrors) {
  const CalibrationResult& r = shared_result();
  ASSERT_EQ(test::checkerboard_images().size(), 13u);
  ASSERT_EQ(r.used_views.size(), 13u);
  EXPECT_TRUE(r.views_without_board.empty());
  ASSERT_EQ(r.per_view_rms.size(), 13u);
  const CameraIntrinsics& c = r.camera.intrinsics;
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  std::printf("[ measured ] RMS %.4f px; fx %.3f fy %.3f cx %.3f cy %.3f; k1 %.5f k2 %.5f p1 %.6f p2 %.6f k3 %.5f\n",
              r.camera.avg_reprojection_error, c.fx, c.fy, c.cx, c.cy, c.distortion[0], c.distortion[1],
              c.distortion[2], c.distortion[3], c.distortion[4]);
  EXPECT_NEAR(r.camera.avg_reprojection_error, 0.409, 0.01);

  double sum_squares = 0, worst = 0;
  std::string worst_view;
  for (std::size_t i = 0; i < r.used_views.size(); ++i) {
    sum_squares += r.per_view_rms[i] * r.per_view_rms[i];
    if (r.per_view_rms[i] > worst) {
      worst = r.per_view_rms[i];
      worst_view = std::filesystem::path(r.used_views[i]).filename().string();
    }
  }
  std::printf("[ measured ] worst view %s at %.4f px\n", worst_view.c_str(), worst);
  EXPECT_EQ(worst_view, "left02.jpg");
  EXPECT_NEAR(worst, 1.22, 0.05);
  // Every view has 54 corners, so the overall RMS is the root mean of the per-view
  // squares: calibrateCamera's own figure against ours from projectPoints.
  EXPECT_NEAR(std::sqrt(sum_squares / 13.0), r.camera.avg_reprojection_error, 1e-5);
}

TEST(CheckerboardCalibration, BundledCameraFileMatchesTheCalibration) {
  const CameraFile file = load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml");
  const CameraFile& computed = shared_result().camera;
  const auto& a = file.intrinsics;
  const auto& b = computed.intrinsics;
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  for (const auto& [x, y] : {std::pair{a.fx, b.fx}, {a.fy, b.fy}, {a.cx, b.cx}, {a.cy, b.cy}})
    EXPECT_NEAR(x, y, 1e-9 * std::abs(y));
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(a.distortion[i], b.distortion[i], 1e-9) << i;
  EXPECT_NEAR(file.avg_reprojection_error, computed.avg_reprojection_error, 1e-12);
}

TEST(CheckerboardCalibration, ViewsWithoutTheBoardAreListed) {
  const Scratch scratch("calib-blank");
  const auto& dir = scratch.dir;
  cv::imwrite((dir / "blank.png").string(), cv::Mat(480, 640, CV_8U, cv::Scalar(128)));
  auto images = test::checkerboard_images();
  images.resize(4);
  images.push_back(dir / "blank.png");
  const CalibrationResult r = calibrate_checkerboard(images, {9, 6}, 0.025);
  EXPECT_EQ(r.used_views.size(), 4u);
  ASSERT_EQ(r.views_without_board.size(), 1u);
  EXPECT_EQ(r.views_without_board[0], (dir / "blank.png").string());
}

TEST(CheckerboardCalibration, ErrorCases) {
  const Scratch scratch("calib-errors");
  const auto& dir = scratch.dir;
  auto images = test::checkerboard_images();

  expect_input_error([&] { calibrate_checkerboard({}, {9, 6}, 0.025); }, "no images");

  std::ofstream(dir / "broken.jpg", std::ios::binary) << "not a jpeg";
  auto with_broken = std::vector<std::filesystem::path>{images[0], dir / "broken.jpg", images[1]};
  expect_input_error([&] { calibrate_checkerboard(with_broken, {9, 6}, 0.025); }, "broken.jpg");
  expect_input_error([&] { calibrate_checkerboard({dir / "missing.jpg"}, {9, 6}, 0.025); }, "missing.jpg");

  cv::Mat small;
  cv::resize(cv::imread(images[2].string()), small, {320, 240}, 0, 0, cv::INTER_AREA);
  cv::imwrite((dir / "small.png").string(), small);
  auto mixed = std::vector<std::filesystem::path>{images[0], images[1], dir / "small.png", images[3]};
  expect_input_error([&] { calibrate_checkerboard(mixed, {9, 6}, 0.025); }, "small.png");

  auto three = std::vector<std::filesystem::path>(images.begin(), images.begin() + 3);
  expect_input_error([&] { calibrate_checkerboard(three, {7, 5}, 0.025); }, "no 7x5");
  auto two = std::vector<std::filesystem::path>(images.begin(), images.begin() + 2);
  expect_input_error([&] { calibrate_checkerboard(two, {9, 6}, 0.025); }, "at least 3");
  expect_input_error([&] { calibrate_checkerboard(three, {9, 6}, 0.0); }, "square size");
}

}  // namespace
}  // namespace lumar::calib
