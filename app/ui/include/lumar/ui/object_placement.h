#pragma once
// Placing a virtual object with the mouse: the ray through a pixel meets the proxy (the
// floor, the table), and the object rests on that surface, its lowest point along the
// surface's normal touching it and the middle of its footprint at the point. Pixels are
// OpenCV's: pixel (c, r) looks along the ray through (c, r) of the undistorted camera
// (docs/conventions.md).
#include <glm/glm.hpp>
#include <optional>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/scene/mesh.h"

namespace lumar::ui {

struct SurfacePoint {
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0, 1.0, 0.0};  // unit, facing the camera that picked it
};

// World ray through `pixel` of a pinhole camera (distortion ignored) at T_world_camera;
// its direction has z = 1 in camera coordinates.
Ray pixel_ray(const CameraIntrinsics& pinhole, const Pose& T_world_camera, const glm::dvec2& pixel);

// The first proxy surface the ray through `pixel` meets, if any.
std::optional<SurfacePoint> surface_at_pixel(const RayScene& proxy, const CameraIntrinsics& pinhole,
                                             const Pose& T_world_camera, const glm::dvec2& pixel);

// T_world_model of `model` turned and scaled by `linear` (model to world: a rotation times
// a uniform scale), resting on the surface at `at`.
glm::dmat4 rest_on_surface(const Mesh& model, const glm::dmat3& linear, const SurfacePoint& at);

// `T_world_model` turned by `degrees` (right-handed) about the normal through `at.point`.
glm::dmat4 turn_on_surface(const glm::dmat4& T_world_model, const SurfacePoint& at, double degrees);

}  // namespace lumar::ui
