// ChArUco calibration on synthetic views: the board as cv::aruco::CharucoBoard::draw
// prints it, seen by a known camera (the webcam's calibration, with its distortion) from
// 12 poses, each pixel mapped exactly through the lens and the board-plane homography.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/calib/board_pose.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/charuco_calibration.h"
#include "lumar/core/error.h"
#include "test_paths.h"

namespace lumar {
namespace {

// The image `camera` sees of `texture` (metres_per_pixel on the board plane, z = 0) at
// T_camera_board; outside the texture is mid grey.
cv::Mat view_of(const cv::Mat& texture, double metres_per_pixel, const CameraIntrinsics& camera,
                const Pose& T_camera_board, const std::vector<cv::Point2d>& rays) {
  const cv::Matx33d R = calib::rotation_matx(T_camera_board);
  cv::Matx33d H(R(0, 0), R(0, 1), T_camera_board.translation.x, R(1, 0), R(1, 1), T_camera_board.translation.y, R(2, 0),
                R(2, 1), T_camera_board.translation.z);
  const cv::Matx33d Hinv = H.inv();
  cv::Mat map_x(camera.height, camera.width, CV_32F), map_y(camera.height, camera.width, CV_32F);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) {
      const cv::Point2d& r = rays[std::size_t(v) * std::size_t(camera.width) + std::size_t(u)];
      const cv::Vec3d b = Hinv * cv::Vec3d(r.x, r.y, 1.0);
      // Texture pixel centres sit at integer coordinates: board point X is pixel X / m - 0.5.
      map_x.at<float>(v, u) = b[2] > 0 ? float(b[0] / b[2] / metres_per_pixel - 0.5) : -1e6f;
      map_y.at<float>(v, u) = b[2] > 0 ? float(b[1] / b[2] / metres_per_pixel - 0.5) : -1e6f;
    }
  cv::Mat out;
  cv::remap(texture, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(128));
  return out;
}

TEST(Charuco, RecoversKnownIntrinsicsFromSyntheticViews) {
  const CameraIntrinsics camera = calib::load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  calib::CharucoBoardSpec spec;  // 7x5 squares of 40 mm, 30 mm DICT_5X5_100 markers
  const double mpp = 0.0002;     // 0.2 mm per texture pixel: 1400 x 1000 pixels
  cv::Mat texture = calib::draw_charuco_board(spec, {1400, 1000});
  // Anti-aliasing: the views shrink the texture about 4 times.
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);

  std::vector<cv::Point2d> pixels, rays;
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) pixels.emplace_back(u, v);
  cv::undistortPoints(pixels, rays, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients(), cv::noArray(),
                      cv::noArray(), cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));

  std::vector<cv::Mat> images;
  const glm::dvec3 centre(0.14, 0.10, 0.0);
  for (int k = 0; k < 12; ++k) {
    const double tilt_x = 30.0 * std::sin(0.9 * k), tilt_y = 30.0 * std::cos(1.3 * k), spin = 10.0 * std::sin(2.1 * k);
    const glm::dquat R = axis_angle_deg({1, 0, 0}, tilt_x) * axis_angle_deg({0, 1, 0}, tilt_y) * axis_angle_deg({0, 0, 1}, spin);
    // Board centre on the optical axis, off-centre by a few centimetres, 0.45 to 0.6 m away.
    const glm::dvec3 at(0.05 * std::sin(1.7 * k), 0.04 * std::cos(2.3 * k), 0.45 + 0.15 * (k % 4) / 3.0);
    images.push_back(view_of(texture, mpp, camera, Pose{R, at - R * centre}, rays));
  }
  const auto result = calib::calibrate_charuco(images, spec);
  const auto& c = result.camera.intrinsics;
  std::printf("ChArUco: %zu views, RMS %.3f px; fx %.2f (true %.2f) fy %.2f (%.2f) cx %.2f (%.2f) cy %.2f (%.2f) "
              "k1 %.4f (%.4f) k2 %.4f (%.4f)\n",
              result.used_views.size(), result.camera.avg_reprojection_error, c.fx, camera.fx, c.fy, camera.fy, c.cx,
              camera.cx, c.cy, camera.cy, c.distortion[0], camera.distortion[0], c.distortion[1], camera.distortion[1]);
  EXPECT_EQ(result.used_views.size(), images.size());
  EXPECT_LT(result.camera.avg_reprojection_error, 0.3);
  EXPECT_NEAR(c.fx, camera.fx, 0.005 * camera.fx);
  EXPECT_NEAR(c.fy, camera.fy, 0.005 * camera.fy);
  EXPECT_NEAR(c.cx, camera.cx, 2.0);
  EXPECT_NEAR(c.cy, camera.cy, 2.0);
  // Radial distortion where the views put corners (normalised radius 0.4, ~210 px from
  // the centre); k1, k2 and k3 trade off against each other, so they are not compared one
  // by one.
  const double r2 = 0.16;
  auto radial = [&](const CameraIntrinsics& k) {
    return 1 + k.distortion[0] * r2 + k.distortion[1] * r2 * r2 + k.distortion[4] * r2 * r2 * r2;
  };
  EXPECT_NEAR(radial(c), radial(camera), 0.002);
  std::printf("radial gain at r = 0.4: %.5f (true %.5f)\n", radial(c), radial(camera));
  EXPECT_GT(result.std_dev[0], 0.0);
}

TEST(Charuco, BadInput) {
  calib::CharucoBoardSpec spec;
  spec.dictionary = "DICT_9X9_1";
  EXPECT_THROW(calib::draw_charuco_board(spec, {700, 500}), InputError);
  spec = {};
  spec.marker_m = 0.05;  // bigger than the square
  EXPECT_THROW(calib::draw_charuco_board(spec, {700, 500}), InputError);
  const std::vector<cv::Mat> blank(3, cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)));
  EXPECT_THROW(calib::calibrate_charuco(blank, {}), InputError);
}

}  // namespace
}  // namespace lumar
