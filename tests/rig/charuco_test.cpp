// ChArUco calibration on synthetic views: the board as cv::aruco::CharucoBoard::draw
// prints it, seen by a known camera (the webcam's calibration, with its distortion) from
// 12 poses (and one of the board curled), each pixel mapped exactly through the lens and the board-plane homography.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/charuco_calibration.h"
#include "lumar/calib/robust_calibration.h"
#include "test_paths.h"

namespace lumar {
namespace {

// The image `camera` sees of `texture` (metres_per_pixel on the board, z = 0) at
// T_camera_board; outside the texture is mid grey. `sag`: the board curls like a sheet
// of paper, z = sag (2 x / width - 1)^2 (its two ends lifted by `sag` metres).
cv::Mat view_of(const cv::Mat& texture, double metres_per_pixel, const CameraIntrinsics& camera,
                const Pose& T_camera_board, const std::vector<cv::Point2d>& rays, double sag = 0.0) {
  const glm::dmat3 Rt = glm::transpose(glm::mat3_cast(T_camera_board.rotation));
  const glm::dvec3 b = Rt * T_camera_board.translation;  // the camera's centre is at -b on the board
  const double half_width = 0.5 * texture.cols * metres_per_pixel, k = sag / (half_width * half_width);
  cv::Mat map_x(camera.height, camera.width, CV_32F), map_y(camera.height, camera.width, CV_32F);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) {
      const cv::Point2d& r = rays[std::size_t(v) * std::size_t(camera.width) + std::size_t(u)];
      const glm::dvec3 a = Rt * glm::dvec3(r.x, r.y, 1.0);  // the ray: board point t a - b
      float x = -1e6f, y = -1e6f;
      if (std::abs(a.z) > 1e-12) {
        double t = b.z / a.z;  // the flat board; a few fixed-point steps onto the curl
        for (int i = 0; i < 8 && k != 0.0; ++i) t = (b.z + k * std::pow(t * a.x - b.x - half_width, 2)) / a.z;
        // Texture pixel centres sit at integer coordinates: board point X is pixel X / m - 0.5.
        if (t > 0)
          x = float((t * a.x - b.x) / metres_per_pixel - 0.5), y = float((t * a.y - b.y) / metres_per_pixel - 0.5);
      }
      map_x.at<float>(v, u) = x;
      map_y.at<float>(v, u) = y;
    }
  cv::Mat out;
  cv::remap(texture, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(128));
  return out;
}

struct CharucoViews {
  CameraIntrinsics camera;       // the webcam's calibration: the truth
  calib::CharucoBoardSpec spec;  // 7x5 squares of 40 mm, 30 mm DICT_5X5_100 markers
  std::vector<calib::NamedImage> images;
};

// 12 views of the board through the true camera, and with `odd_view` one more that
// cannot agree with the others.
const CharucoViews& charuco_views(bool odd_view) {
  static CharucoViews views[2];
  CharucoViews& v = views[odd_view ? 1 : 0];
  if (!v.images.empty()) return v;
  v.camera = calib::load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  const double mpp = 0.0002;  // 0.2 mm per texture pixel: 1400 x 1000 pixels
  cv::Mat texture = calib::draw_charuco_board(v.spec, {1400, 1000});
  // Anti-aliasing: the views shrink the texture about 4 times.
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);
  std::vector<cv::Point2d> pixels, rays;
  for (int y = 0; y < v.camera.height; ++y)
    for (int x = 0; x < v.camera.width; ++x) pixels.emplace_back(x, y);
  cv::undistortPoints(pixels, rays, cv::Mat(v.camera.camera_matrix()), v.camera.distortion_coefficients(),
                      cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
  const glm::dvec3 centre(0.14, 0.10, 0.0);
  auto pose = [&](int k) {
    const double tilt_x = 30.0 * std::sin(0.9 * k), tilt_y = 30.0 * std::cos(1.3 * k), spin = 10.0 * std::sin(2.1 * k);
    const glm::dquat R =
        axis_angle_deg({1, 0, 0}, tilt_x) * axis_angle_deg({0, 1, 0}, tilt_y) * axis_angle_deg({0, 0, 1}, spin);
    // Board centre on the optical axis, off-centre by a few centimetres, 0.45 to 0.6 m away.
    const glm::dvec3 at(0.05 * std::sin(1.7 * k), 0.04 * std::cos(2.3 * k), 0.45 + 0.15 * (k % 4) / 3.0);
    return Pose{R, at - R * centre};
  };
  for (int k = 0; k < 12; ++k)
    v.images.push_back({"view" + std::to_string(k), view_of(texture, mpp, v.camera, pose(k), rays)});
  // A board printed on paper that curled: its ends 1.5 cm off the plane.
  if (odd_view) v.images.push_back({"curled", view_of(texture, mpp, v.camera, pose(12), rays, 0.015)});
  return v;
}

TEST(Charuco, RecoversKnownIntrinsicsFromSyntheticViews) {
  const CharucoViews& v = charuco_views(false);
  const calib::BoardViews views = calib::detect_charuco_views(v.images, v.spec);
  const auto result = calib::calibrate_robust(views);
  const CameraIntrinsics& camera = v.camera;
  const auto& c = result.camera.intrinsics;
  std::printf(
      "ChArUco: %zu views, RMS %.3f px; fx %.2f (true %.2f) fy %.2f (%.2f) cx %.2f (%.2f) cy %.2f (%.2f) "
      "k1 %.4f (%.4f) k2 %.4f (%.4f)\n",
      result.used_views.size(), result.camera.avg_reprojection_error, c.fx, camera.fx, c.fy, camera.fy, c.cx, camera.cx,
      c.cy, camera.cy, c.distortion[0], camera.distortion[0], c.distortion[1], camera.distortion[1]);
  EXPECT_EQ(result.used_views.size(), v.images.size());
  EXPECT_TRUE(result.rejected.empty());
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
  // Partly visible boards: each view's points are the corners it found, on the board.
  for (std::size_t i = 0; i < views.corners.size(); ++i) ASSERT_EQ(views.corners[i].size(), views.objects[i].size());
}

TEST(Charuco, CurledBoardViewIsRejected) {
  const CharucoViews& v = charuco_views(true);
  const auto result = calib::calibrate_robust(calib::detect_charuco_views(v.images, v.spec));
  std::printf("ChArUco with a curled board: RMS all views %.3f px, kept %.3f px;", result.initial_rms,
              result.camera.avg_reprojection_error);
  for (const auto& r : result.rejected)
    std::printf(" rejected %s (%.3f px > %.3f px)", r.name.c_str(), r.rms_px, r.threshold_px);
  for (std::size_t i = 0; i < result.used_views.size(); ++i)
    if (result.used_views[i] == "curled") std::printf(" curled view kept at %.3f px", result.per_view_rms[i]);
  for (const auto& name : result.views_without_board) std::printf(" no board in %s", name.c_str());
  std::printf("\n");
  ASSERT_EQ(result.rejected.size(), 1u);
  EXPECT_EQ(result.rejected[0].name, "curled");
  EXPECT_EQ(result.used_views.size(), 12u);
  EXPECT_LT(result.camera.avg_reprojection_error, 0.3);
  EXPECT_NEAR(result.camera.intrinsics.fx, v.camera.fx, 0.005 * v.camera.fx);
}

// The same views as files through `lumar calibrate --charuco`: the curled board is
// named in views_rejected without being pointed out.
TEST(Charuco, CalibrateCommandRejectsTheCurledBoard) {
  const CharucoViews& v = charuco_views(true);
  const test::Scratch scratch("charuco-cli");
  for (const auto& image : v.images) cv::imwrite((scratch.dir / (image.name + ".png")).string(), image.image);
  const auto json_path = scratch.dir / "summary.json";
  const std::string command = "'" + test::lumar_binary().string() + "' calibrate --images '" +
                              (scratch.dir / "*.png").string() +
                              "' --charuco 7x5 --square 0.04 --marker 0.03 --dict DICT_5X5_100 --json --out '" +
                              (scratch.dir / "camera.yml").string() + "' > '" + json_path.string() + "' 2>/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const auto summary = nlohmann::json::parse(std::ifstream(json_path));
  const std::string curled = (scratch.dir / "curled.png").string();
  EXPECT_EQ(summary["views_rejected"], nlohmann::json::array({curled}));
  EXPECT_EQ(summary["views_used"], 12);
  EXPECT_LT(summary["rms"].get<double>(), 0.3);
  EXPECT_NEAR(summary["fx"].get<double>(), v.camera.fx, 0.005 * v.camera.fx);
  // The written calibration reads back as a camera file with the same focal length.
  EXPECT_NEAR(calib::load_camera_file(scratch.dir / "camera.yml").intrinsics.fx, summary["fx"].get<double>(), 1e-6);
}

TEST(Charuco, BadInput) {
  calib::CharucoBoardSpec spec;
  spec.dictionary = "DICT_9X9_1";
  EXPECT_THROW(calib::draw_charuco_board(spec, {700, 500}), InputError);
  spec = {};
  spec.marker_m = 0.05;  // bigger than the square
  EXPECT_THROW(calib::draw_charuco_board(spec, {700, 500}), InputError);
  const cv::Mat blank(480, 640, CV_8UC1, cv::Scalar(128));
  EXPECT_THROW(calib::detect_charuco_views({{"a", blank}, {"b", blank}, {"c", blank}}, {}), InputError);
  EXPECT_THROW(calib::detect_charuco_views({}, {}), InputError);
  const cv::Mat small(240, 320, CV_8UC1, cv::Scalar(128));
  EXPECT_THROW(calib::detect_charuco_views({{"a", blank}, {"small", small}}, {}), InputError);
}

}  // namespace
}  // namespace lumar
