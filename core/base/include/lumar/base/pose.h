#pragma once
// Rigid transforms. Naming: T_a_b maps points from frame b to frame a, so
// T_a_c = T_a_b * T_b_c. Camera to world is
// T_world_camera = T_world_transmitter * T_transmitter_sensor * T_sensor_camera.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace lumar {

struct Pose {
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // unit quaternion (w, x, y, z)
  glm::dvec3 translation{0.0};

  static Pose from_matrix(const glm::dmat4& m);  // m must be rigid
  glm::dmat4 matrix() const;
  glm::dmat3 rotation_matrix() const { return glm::mat3_cast(rotation); }

  glm::dvec3 apply(const glm::dvec3& p) const { return rotation * p + translation; }
  Pose inverse() const;
  Pose operator*(const Pose& b) const;  // this ∘ b
  bool is_finite() const;
};

// Rotation about a unit axis by an angle in degrees.
glm::dquat axis_angle_deg(const glm::dvec3& axis, double angle_deg);

// Angle of the relative rotation between a and b, in degrees (0..180).
double rotation_angle_deg(const glm::dquat& a, const glm::dquat& b);

// SO(3)'s log and exp: the rotation vector (axis * angle, radians, angle in [0, pi], the
// short way) of a quaternion, and back.
glm::dvec3 rotation_log(const glm::dquat& q);
glm::dquat rotation_exp(const glm::dvec3& v);

// Shortest-path slerp of rotation and linear interpolation of translation, s in [0, 1].
Pose interpolate(const Pose& a, const Pose& b, double s);

// Polhemus attitude (azimuth, elevation, roll in degrees): R = Rz(az) * Ry(el) * Rx(roll).
// Used only at the edge of tracking/; nothing past it sees Euler angles.
glm::dquat polhemus_attitude_to_quat(double azimuth_deg, double elevation_deg, double roll_deg);
// Inverse of the above; elevation in [-90, 90], azimuth and roll in (-180, 180].
glm::dvec3 quat_to_polhemus_attitude(const glm::dquat& q);

}  // namespace lumar
