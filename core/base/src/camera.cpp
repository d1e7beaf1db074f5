#include "lumar/base/camera.h"

#include <cmath>

namespace lumar {

cv::Mat CameraIntrinsics::distortion_coefficients() const {
  cv::Mat d(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) d.at<double>(i) = distortion[i];
  return d;
}

CameraIntrinsics CameraIntrinsics::without_distortion() const {
  CameraIntrinsics c = *this;
  c.distortion = {};
  return c;
}

bool CameraIntrinsics::has_distortion() const {
  for (double k : distortion)
    if (k != 0.0) return true;
  return false;
}

bool CameraIntrinsics::is_valid() const {
  bool finite = std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy);
  for (double k : distortion) finite = finite && std::isfinite(k);
  return finite && width > 0 && height > 0 && fx > 0 && fy > 0;
}

glm::dvec2 project_pinhole(const CameraIntrinsics& c, const glm::dvec3& p) {
  return {c.fx * p.x / p.z + c.cx, c.fy * p.y / p.z + c.cy};
}

glm::dvec2 project_distorted(const CameraIntrinsics& c, const glm::dvec3& p) {
  const double x = p.x / p.z, y = p.y / p.z;
  const auto& [k1, k2, p1, p2, k3] = c.distortion;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {c.fx * xd + c.cx, c.fy * yd + c.cy};
}

glm::dmat4 opengl_projection(const CameraIntrinsics& c, double n, double f) {
  // Derivation in docs/conventions.md: x_window = u + 0.5, y_window = H - v - 0.5.
  const double W = c.width, H = c.height;
  glm::dmat4 P(0.0);  // P[col][row]
  P[0][0] = 2.0 * c.fx / W;
  P[2][0] = 1.0 - (2.0 * c.cx + 1.0) / W;
  P[1][1] = 2.0 * c.fy / H;
  P[2][1] = (2.0 * c.cy + 1.0) / H - 1.0;
  P[2][2] = -(f + n) / (f - n);
  P[3][2] = -2.0 * f * n / (f - n);
  P[2][3] = -1.0;
  return P;
}

glm::dmat4 opengl_view(const Pose& T_world_camera) {
  // eye = diag(1, -1, -1) * T_camera_world
  const glm::dmat4 flip =
      glm::dmat4(glm::dvec4(1, 0, 0, 0), glm::dvec4(0, -1, 0, 0), glm::dvec4(0, 0, -1, 0), glm::dvec4(0, 0, 0, 1));
  return flip * T_world_camera.inverse().matrix();
}

}  // namespace lumar
