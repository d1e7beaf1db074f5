#include "lumar/base/pose.h"

#include <algorithm>
#include <cmath>

namespace lumar {

Pose Pose::from_matrix(const glm::dmat4& m) {
  Pose p;
  p.rotation = glm::normalize(glm::quat_cast(glm::dmat3(m)));
  p.translation = glm::dvec3(m[3]);
  return p;
}

glm::dmat4 Pose::matrix() const {
  glm::dmat4 m(glm::mat3_cast(rotation));
  m[3] = glm::dvec4(translation, 1.0);
  return m;
}

Pose Pose::inverse() const {
  Pose p;
  p.rotation = glm::conjugate(rotation);
  p.translation = -(p.rotation * translation);
  return p;
}

Pose Pose::operator*(const Pose& b) const {
  Pose p;
  p.rotation = glm::normalize(rotation * b.rotation);
  p.translation = rotation * b.translation + translation;
  return p;
}

bool Pose::is_finite() const {
  for (int i = 0; i < 4; ++i)
    if (!std::isfinite(rotation[i])) return false;
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(translation[i])) return false;
  return std::abs(glm::length(rotation) - 1.0) < 1e-3;
}

glm::dquat axis_angle_deg(const glm::dvec3& axis, double angle_deg) {
  return glm::angleAxis(glm::radians(angle_deg), glm::normalize(axis));
}

double rotation_angle_deg(const glm::dquat& a, const glm::dquat& b) {
  // atan2 of the relative rotation keeps precision near zero, where acos does not.
  const glm::dquat r = glm::conjugate(glm::normalize(a)) * glm::normalize(b);
  const double s = glm::length(glm::dvec3(r.x, r.y, r.z));
  return glm::degrees(2.0 * std::atan2(s, std::abs(r.w)));
}

glm::dvec3 rotation_log(const glm::dquat& q_in) {
  glm::dquat q = glm::normalize(q_in);
  if (q.w < 0) q = -q;
  const glm::dvec3 axis(q.x, q.y, q.z);
  const double s = glm::length(axis);
  if (s < 1e-12) return 2.0 * axis;
  return axis * (2.0 * std::atan2(s, q.w) / s);
}

glm::dquat rotation_exp(const glm::dvec3& v) {
  const double angle = glm::length(v);
  if (angle < 1e-12) return glm::normalize(glm::dquat(1.0, 0.5 * v.x, 0.5 * v.y, 0.5 * v.z));
  return glm::angleAxis(angle, v / angle);
}

Pose interpolate(const Pose& a, const Pose& b, double s) {
  Pose p;
  glm::dquat qb = glm::dot(a.rotation, b.rotation) < 0 ? -b.rotation : b.rotation;
  p.rotation = glm::normalize(glm::slerp(a.rotation, qb, s));
  p.translation = glm::mix(a.translation, b.translation, s);
  return p;
}

glm::dquat polhemus_attitude_to_quat(double azimuth_deg, double elevation_deg, double roll_deg) {
  const glm::dquat qz = glm::angleAxis(glm::radians(azimuth_deg), glm::dvec3(0, 0, 1));
  const glm::dquat qy = glm::angleAxis(glm::radians(elevation_deg), glm::dvec3(0, 1, 0));
  const glm::dquat qx = glm::angleAxis(glm::radians(roll_deg), glm::dvec3(1, 0, 0));
  return glm::normalize(qz * qy * qx);
}

glm::dvec3 quat_to_polhemus_attitude(const glm::dquat& q) {
  // R = Rz(a) Ry(e) Rx(r): R20 = -sin e, R21 = cos e sin r, R22 = cos e cos r,
  // R10 = sin a cos e, R00 = cos a cos e. glm matrices are column-major: R[col][row].
  const glm::dmat3 R = glm::mat3_cast(glm::normalize(q));
  const double r20 = R[0][2], r21 = R[1][2], r22 = R[2][2], r10 = R[0][1], r00 = R[0][0];
  const double el = std::asin(std::clamp(-r20, -1.0, 1.0));
  double az, roll;
  if (std::abs(r20) < 1.0 - 1e-12) {
    az = std::atan2(r10, r00);
    roll = std::atan2(r21, r22);
  } else {  // gimbal lock: fold roll into azimuth
    az = std::atan2(-R[1][0], R[1][1]);
    roll = 0.0;
  }
  return {glm::degrees(az), glm::degrees(el), glm::degrees(roll)};
}

}  // namespace lumar
