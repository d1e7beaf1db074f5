// Conventions every module relies on, checked against independent formulas:
// lat-long mapping, pose composition, Polhemus attitude, OpenCV <-> OpenGL camera.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <random>

#include "lumar/base/camera.h"
#include "lumar/base/constants.h"
#include "lumar/base/latlong.h"
#include "lumar/base/pose.h"

using namespace lumar;

namespace {
glm::dquat random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return glm::normalize(glm::dquat(n(rng), n(rng), n(rng), n(rng)));
}
glm::dmat3 Rx(double a) {
  double c = cos(a), s = sin(a);
  return glm::transpose(glm::dmat3(1, 0, 0, 0, c, -s, 0, s, c));
}
glm::dmat3 Ry(double a) {
  double c = cos(a), s = sin(a);
  return glm::transpose(glm::dmat3(c, 0, s, 0, 1, 0, -s, 0, c));
}
glm::dmat3 Rz(double a) {
  double c = cos(a), s = sin(a);
  return glm::transpose(glm::dmat3(c, -s, 0, s, c, 0, 0, 0, 1));
}
double max_abs_diff(const glm::dmat3& a, const glm::dmat3& b) {
  double m = 0;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) m = std::max(m, std::abs(a[c][r] - b[c][r]));
  return m;
}
}  // namespace

TEST(LatLong, KnownDirections) {
  const int W = 64, H = 32;
  // Top edge looks up, the middle row looks at the horizon, u = 0 is +X, u = W/4 is +Z.
  EXPECT_NEAR(latlong_direction(5.0, 0.0, W, H).y, 1.0, 1e-12);
  auto d = latlong_direction(0.0, H / 2.0, W, H);
  EXPECT_NEAR(d.x, 1.0, 1e-12);
  d = latlong_direction(W / 4.0, H / 2.0, W, H);
  EXPECT_NEAR(d.z, 1.0, 1e-12);
  d = latlong_direction(W / 2.0, H / 2.0, W, H);
  EXPECT_NEAR(d.x, -1.0, 1e-12);
  // Pixel centres follow the formula of ARCHITECTURE.md written out independently.
  for (int r : {0, 7, 31})
    for (int c : {0, 13, 63}) {
      const double phi = 2 * kPi * (c + 0.5) / W, theta = kPi * (r + 0.5) / H;
      const glm::dvec3 e(sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi));
      const auto got = latlong_pixel_direction(c, r, W, H);
      EXPECT_NEAR(glm::length(got - e), 0.0, 1e-12);
    }
}

TEST(LatLong, RoundTripAndSolidAngle) {
  const int W = 1024, H = 512;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, W), v(0.01, H - 0.01);
  for (int i = 0; i < 1000; ++i) {
    const double uu = u(rng), vv = v(rng);
    const auto back = latlong_coordinates(latlong_direction(uu, vv, W, H) * 3.7, W, H);
    EXPECT_NEAR(back.x, uu, 1e-7);
    EXPECT_NEAR(back.y, vv, 1e-7);
  }
  double total = 0;
  for (int r = 0; r < H; ++r) total += latlong_pixel_solid_angle(r, W, H) * W;
  EXPECT_NEAR(total, 4 * kPi, 1e-9);
}

TEST(Pose, CompositionMatchesMatrices) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> t(-2, 2);
  for (int i = 0; i < 100; ++i) {
    Pose a{random_rotation(rng), {t(rng), t(rng), t(rng)}};
    Pose b{random_rotation(rng), {t(rng), t(rng), t(rng)}};
    const glm::dvec3 p(t(rng), t(rng), t(rng));
    const glm::dvec4 via_matrix = a.matrix() * b.matrix() * glm::dvec4(p, 1);
    EXPECT_NEAR(glm::length((a * b).apply(p) - glm::dvec3(via_matrix)), 0, 1e-12);
    EXPECT_NEAR(glm::length(a.inverse().apply(a.apply(p)) - p), 0, 1e-12);
    const Pose back = Pose::from_matrix(a.matrix());
    EXPECT_LT(rotation_angle_deg(back.rotation, a.rotation), 1e-6);
    EXPECT_NEAR(glm::length(back.translation - a.translation), 0, 1e-12);
  }
}

TEST(Pose, RigChainMapsCameraToWorld) {
  // A point 1 m in front of the camera, camera 0.1 m along the sensor's x axis,
  // sensor 0.5 m along the transmitter's z axis (down), transmitter rotated so its
  // +Z points down the world's -Y, 1 m above the origin.
  Pose T_world_transmitter{axis_angle_deg({1, 0, 0}, 90), {0, 1, 0}};
  Pose T_transmitter_sensor{glm::dquat(1, 0, 0, 0), {0, 0, 0.5}};
  Pose T_sensor_camera{glm::dquat(1, 0, 0, 0), {0.1, 0, 0}};
  const Pose T_world_camera = T_world_transmitter * T_transmitter_sensor * T_sensor_camera;
  const glm::dvec3 p = T_world_camera.apply({0, 0, 1});  // 1 m further along transmitter +Z
  EXPECT_NEAR(p.x, 0.1, 1e-12);
  EXPECT_NEAR(p.y, 1.0 - 1.5, 1e-12);
  EXPECT_NEAR(p.z, 0.0, 1e-12);
}

TEST(Pose, PolhemusAttitudeIsRzRyRx) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> az(-179, 179), el(-89, 89);
  for (int i = 0; i < 200; ++i) {
    const double a = az(rng), e = el(rng), r = az(rng);
    const glm::dmat3 expected = Rz(glm::radians(a)) * Ry(glm::radians(e)) * Rx(glm::radians(r));
    const glm::dquat q = polhemus_attitude_to_quat(a, e, r);
    EXPECT_LT(max_abs_diff(glm::mat3_cast(q), expected), 1e-12);
    const glm::dvec3 back = quat_to_polhemus_attitude(q);
    EXPECT_NEAR(back.x, a, 1e-7);
    EXPECT_NEAR(back.y, e, 1e-7);
    EXPECT_NEAR(back.z, r, 1e-7);
  }
  // Azimuth 90 turns the sensor's +X onto the transmitter's +Y.
  const glm::dvec3 x = polhemus_attitude_to_quat(90, 0, 0) * glm::dvec3(1, 0, 0);
  EXPECT_NEAR(x.y, 1.0, 1e-12);
}

TEST(Pose, InterpolationFollowsConstantAngularVelocity) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(1, 2, 3));
  Pose a{axis_angle_deg(axis, 10), {0, 0, 0}};
  Pose b{axis_angle_deg(axis, 50), {1, 2, 3}};
  b.rotation = -b.rotation;  // same rotation, other hemisphere: must still take the short way
  const Pose m = interpolate(a, b, 0.25);
  EXPECT_LT(rotation_angle_deg(m.rotation, axis_angle_deg(axis, 20)), 1e-9);
  EXPECT_NEAR(glm::length(m.translation - glm::dvec3(0.25, 0.5, 0.75)), 0, 1e-12);
}

TEST(Pose, RotationLogAndExpRoundTrip) {
  for (const glm::dvec3 v :
       {glm::dvec3(0.3, -0.2, 0.5), glm::dvec3(0.1, -0.2, 0.3), glm::dvec3(3.0, 0, 0), glm::dvec3(1e-9, 0, 0)})
    EXPECT_LT(glm::length(rotation_log(rotation_exp(v)) - v), 1e-12);
  EXPECT_NEAR(rotation_angle_deg(rotation_exp(glm::dvec3(0, glm::radians(30.0), 0)), glm::dquat(1, 0, 0, 0)), 30.0,
              1e-9);
  EXPECT_NEAR(glm::length(rotation_log(glm::dquat(1, 0, 0, 0))), 0.0, 1e-15);
  // The short way: q and -q are one rotation.
  const glm::dquat q = rotation_exp({0, 0.4, 0});
  EXPECT_LT(glm::length(rotation_log(-q) - glm::dvec3(0, 0.4, 0)), 1e-12);
}

TEST(Camera, DistortedProjectionMatchesOpenCV) {
  CameraIntrinsics c{640, 480, 536.1, 536.0, 342.4, 235.5, {-0.27, 0.09, 0.0012, -0.0004, 0.02}};
  std::vector<cv::Point3d> pts;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> xy(-0.6, 0.6), z(0.8, 4.0);
  for (int i = 0; i < 200; ++i) {
    const double zz = z(rng);
    pts.emplace_back(xy(rng) * zz, xy(rng) * zz, zz);
  }
  std::vector<cv::Point2d> cv_px;
  cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv::Mat(c.camera_matrix()),
                    c.distortion_coefficients(), cv_px);
  for (size_t i = 0; i < pts.size(); ++i) {
    const auto p = project_distorted(c, {pts[i].x, pts[i].y, pts[i].z});
    EXPECT_NEAR(p.x, cv_px[i].x, 1e-9);
    EXPECT_NEAR(p.y, cv_px[i].y, 1e-9);
  }
}

TEST(Camera, OpenGLMatricesLandWhereOpenCVProjects) {
  const CameraIntrinsics c{640, 480, 536.1, 530.7, 342.4, 235.5, {}};
  std::mt19937 rng(7);
  const Pose T_world_camera{random_rotation(rng), {0.3, 1.4, -2.0}};
  const glm::dmat4 P = opengl_projection(c, 0.05, 50.0), V = opengl_view(T_world_camera);
  std::uniform_real_distribution<double> xy(-0.5, 0.5), z(0.2, 20.0);
  std::vector<cv::Point3d> world;
  std::vector<glm::dvec3> world_glm;
  for (int i = 0; i < 300; ++i) {
    const double zz = z(rng);
    const glm::dvec3 w = T_world_camera.apply({xy(rng) * zz, xy(rng) * zz, zz});
    world_glm.push_back(w);
    world.emplace_back(w.x, w.y, w.z);
  }
  // OpenCV: rvec/tvec of T_camera_world.
  const Pose T_camera_world = T_world_camera.inverse();
  cv::Matx33d R;
  const glm::dmat3 Rg = T_camera_world.rotation_matrix();
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) R(r, col) = Rg[col][r];
  cv::Vec3d rvec, tvec(T_camera_world.translation.x, T_camera_world.translation.y, T_camera_world.translation.z);
  cv::Rodrigues(R, rvec);
  std::vector<cv::Point2d> px;
  cv::projectPoints(world, rvec, tvec, cv::Mat(c.camera_matrix()), cv::Mat(), px);
  for (size_t i = 0; i < world.size(); ++i) {
    const glm::dvec4 clip = P * V * glm::dvec4(world_glm[i], 1.0);
    ASSERT_GT(clip.w, 0);
    const double x_ndc = clip.x / clip.w, y_ndc = clip.y / clip.w, z_ndc = clip.z / clip.w;
    const double x_window = (x_ndc + 1) * 0.5 * c.width, y_window = (y_ndc + 1) * 0.5 * c.height;
    // OpenCV pixel (u, v) has its centre at window (u + 0.5, H - v - 0.5).
    EXPECT_NEAR(x_window, px[i].x + 0.5, 1e-7);
    EXPECT_NEAR(y_window, c.height - px[i].y - 0.5, 1e-7);
    EXPECT_GT(z_ndc, -1.0);
    EXPECT_LT(z_ndc, 1.0);
    // Round trip: window + depth back through the inverse matrices gives the world point.
    const glm::dvec4 back = glm::inverse(P * V) * glm::dvec4(x_ndc, y_ndc, z_ndc, 1.0);
    EXPECT_NEAR(glm::length(glm::dvec3(back) / back.w - world_glm[i]), 0, 1e-6);
  }
}
