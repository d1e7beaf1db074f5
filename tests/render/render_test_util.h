#pragma once
// Shared pieces of the renderer tests: one headless context per process, camera poses
// (meshes built in code are in test_geometry.h).
#include <opencv2/core.hpp>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"
#include "lumar/lighting/sh.h"
#include "lumar/render/platform/context.h"
#include "lumar/scene/mesh.h"
#include "test_geometry.h"

namespace lumar::test {

// A surfaceless EGL context, made current; created on first use, kept for the process.
gl::Context& headless_context();

// OpenCV camera at `eye` looking at `target` (+Y world up), rolled by `roll_deg` about its view axis.
Pose look_at(const glm::dvec3& eye, const glm::dvec3& target, double roll_deg = 0.0);

// OpenCV rvec / tvec of T_camera_world for cv::projectPoints.
void rvec_tvec(const Pose& T_world_camera, cv::Mat& rvec, cv::Mat& tvec);

// Real SH basis in world coordinates, order L00, L1-1(y), L10(z), L11(x), L2-2(xy),
// L2-1(yz), L20(3z^2-1), L21(xz), L22(x^2-y^2).
std::array<double, 9> sh_basis(const glm::dvec3& d);
// Ramamoorthi & Hanrahan irradiance from nine coefficients (CPU reference), not clamped.
glm::dvec3 sh_irradiance_reference(const SH9& sh, const glm::dvec3& n);

CameraIntrinsics make_camera(int w, int h, double fx, double fy, double cx, double cy);

// Nine coefficients of a uniform incoming radiance: E = pi * radiance everywhere, so a
// surface of albedo a at exposure 1 has the linear value a * radiance.
SH9 uniform_sh(double radiance);
// A BGR8 sRGB image's linear values (CV_32FC3, BGR).
cv::Mat linear_of(const cv::Mat& bgr8);

}  // namespace lumar::test
