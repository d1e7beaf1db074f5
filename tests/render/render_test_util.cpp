#include "render_test_util.h"

#include <cmath>
#include <memory>
#include <numbers>
#include <opencv2/calib3d.hpp>

#include "lumar/base/color.h"

namespace lumar::test {

gl::Context& headless_context() {
  static std::unique_ptr<gl::Context> context = gl::create_headless_context();
  context->make_current();
  return *context;
}

Pose look_at(const glm::dvec3& eye, const glm::dvec3& target, double roll_deg) {
  const glm::dvec3 z = glm::normalize(target - eye);                        // forward
  const glm::dvec3 x = glm::normalize(glm::cross(z, glm::dvec3(0, 1, 0)));  // right
  const glm::dvec3 y = glm::cross(z, x);                                    // down
  glm::dmat4 m(1.0);
  m[0] = glm::dvec4(x, 0);
  m[1] = glm::dvec4(y, 0);
  m[2] = glm::dvec4(z, 0);
  m[3] = glm::dvec4(eye, 1);
  Pose pose = Pose::from_matrix(m);
  pose.rotation = glm::normalize(pose.rotation * axis_angle_deg({0, 0, 1}, roll_deg));
  return pose;
}

void rvec_tvec(const Pose& T_world_camera, cv::Mat& rvec, cv::Mat& tvec) {
  const Pose T_camera_world = T_world_camera.inverse();
  const glm::dmat3 R = T_camera_world.rotation_matrix();  // R[col][row]
  cv::Matx33d Rcv;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Rcv(r, c) = R[c][r];
  cv::Rodrigues(Rcv, rvec);
  const glm::dvec3 t = T_camera_world.translation;
  tvec = (cv::Mat_<double>(3, 1) << t.x, t.y, t.z);
}

std::array<double, 9> sh_basis(const glm::dvec3& d) {
  const double x = d.x, y = d.y, z = d.z;
  return {0.282095,
          0.488603 * y,
          0.488603 * z,
          0.488603 * x,
          1.092548 * x * y,
          1.092548 * y * z,
          0.315392 * (3 * z * z - 1),
          1.092548 * x * z,
          0.546274 * (x * x - y * y)};
}

glm::dvec3 sh_irradiance_reference(const SH9& sh, const glm::dvec3& n) {
  const double c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708;
  const auto& L = sh.coefficients;
  const double x = n.x, y = n.y, z = n.z;
  return c1 * L[8] * (x * x - y * y) + c3 * L[6] * z * z + c4 * L[0] - c5 * L[6] +
         2 * c1 * (L[4] * x * y + L[7] * x * z + L[5] * y * z) + 2 * c2 * (L[3] * x + L[1] * y + L[2] * z);
}

CameraIntrinsics make_camera(int w, int h, double fx, double fy, double cx, double cy) {
  CameraIntrinsics c;
  c.width = w;
  c.height = h;
  c.fx = fx;
  c.fy = fy;
  c.cx = cx;
  c.cy = cy;
  return c;
}

SH9 uniform_sh(double radiance) {
  SH9 sh;
  sh.coefficients[0] = glm::dvec3(radiance * 0.282095 * 4.0 * std::numbers::pi);  // ∫ L Y00 dω
  return sh;
}

cv::Mat linear_of(const cv::Mat& bgr8) {
  cv::Mat out(bgr8.size(), CV_32FC3);
  for (int r = 0; r < bgr8.rows; ++r)
    for (int c = 0; c < bgr8.cols; ++c)
      for (int k = 0; k < 3; ++k)
        out.at<cv::Vec3f>(r, c)[k] = srgb_to_linear(float(bgr8.at<cv::Vec3b>(r, c)[k]) / 255.0f);
  return out;
}

}  // namespace lumar::test
