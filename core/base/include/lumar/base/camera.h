#pragma once
// Pinhole camera with Brown–Conrady distortion, in OpenCV's convention: x right,
// y down, z forward; pixel (u, v) with the centre of the top-left pixel at (0, 0).
// OpenGL matrices are made here and used only by the renderer.
#include <array>
#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "lumar/base/pose.h"

namespace lumar {

struct CameraIntrinsics {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 5> distortion{};  // k1 k2 p1 p2 k3

  cv::Matx33d camera_matrix() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
  cv::Mat distortion_coefficients() const;  // 1x5 CV_64F
  CameraIntrinsics without_distortion() const;
  bool has_distortion() const;
  bool is_valid() const;  // positive size and focal lengths, finite numbers
};

// Pinhole projection (no distortion) of a point in camera coordinates.
glm::dvec2 project_pinhole(const CameraIntrinsics& camera, const glm::dvec3& p_camera);
// Projection with the camera's lens distortion (same model as cv::projectPoints).
glm::dvec2 project_distorted(const CameraIntrinsics& camera, const glm::dvec3& p_camera);

// OpenGL clip-from-eye matrix for the undistorted camera: a point that OpenCV puts
// at pixel (u, v) lands at window coordinates (u + 0.5, H - v - 0.5), i.e. in the
// pixel whose centre OpenCV calls (u, v) once the read-back image is flipped to row 0
// at the top.
glm::dmat4 opengl_projection(const CameraIntrinsics& camera, double near_m, double far_m);
// OpenGL eye-from-world matrix for a camera pose: OpenCV camera axes (x right, y down,
// z forward) become OpenGL eye axes (x right, y up, -z forward).
glm::dmat4 opengl_view(const Pose& T_world_camera);

}  // namespace lumar
