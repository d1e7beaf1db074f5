#include "render_test_util.h"

#include <cmath>
#include <memory>
#include <numbers>
#include <opencv2/calib3d.hpp>

namespace lumar::test {

gl::Context& headless_context() {
  static std::unique_ptr<gl::Context> context = gl::create_headless_context();
  context->make_current();
  return *context;
}

Mesh make_sphere(const glm::vec3& centre, float radius, int slices, int stacks) {
  Mesh m;
  for (int i = 0; i <= stacks; ++i) {
    const double theta = std::numbers::pi * i / stacks;
    for (int j = 0; j <= slices; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / slices;
      const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(centre + radius * n);
      m.normals.push_back(n);
    }
  }
  const auto index = [&](int i, int j) { return std::uint32_t(i * (slices + 1) + j); };
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      m.indices.insert(m.indices.end(), {index(i, j), index(i + 1, j), index(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {index(i, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  return m;
}

Mesh make_box(const glm::vec3& lo, const glm::vec3& hi, bool inward) {
  Mesh m;
  // Each face: outward normal axis/sign, four corners.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      glm::vec3 n(0.0f);
      n[axis] = side ? 1.0f : -1.0f;
      const std::uint32_t base = std::uint32_t(m.positions.size());
      for (int k = 0; k < 4; ++k) {
        glm::vec3 p;
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = (k == 1 || k == 2) ? hi[u] : lo[u];
        p[v] = (k >= 2) ? hi[v] : lo[v];
        m.positions.push_back(p);
        m.normals.push_back(inward ? -n : n);
      }
      // Corners 0-1-2-3 run counter-clockwise seen from +axis; reverse them where the
      // front (the side the normal points to) faces the other way.
      if ((side == 1) != inward)
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
      else
        m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    }
  return m;
}

Mesh make_quad(const glm::vec3& centre, const glm::vec3& a, const glm::vec3& b, const glm::vec3& normal) {
  Mesh m;
  m.positions = {centre - a - b, centre + a - b, centre + a + b, centre - a + b};
  m.normals.assign(4, glm::normalize(normal));
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
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
  return {0.282095,           0.488603 * y,     0.488603 * z,
          0.488603 * x,       1.092548 * x * y, 1.092548 * y * z,
          0.315392 * (3 * z * z - 1), 1.092548 * x * z, 0.546274 * (x * x - y * y)};
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

}  // namespace lumar::test
