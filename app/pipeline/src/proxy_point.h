#pragma once
// The point of the proxy a camera ray meets, for image-aided tracking: the ray through a
// point of the normalised image plane (x, y, 1) from `T_world_camera`.
#include <opencv2/core.hpp>
#include <optional>

#include "lumar/base/pose.h"
#include "lumar/lighting/ray_scene.h"

namespace lumar::pipeline {

// Nothing when the ray misses, meets a back face, or grazes the surface (below 0.15 of
// head-on), where a small error in the pose puts the point far off.
inline std::optional<cv::Point3f> point_on_proxy(const RayScene& proxy, const Pose& T_world_camera,
                                                 const cv::Point2f& normalised) {
  Ray ray;
  const glm::dvec3 d = T_world_camera.rotation * glm::dvec3(normalised.x, normalised.y, 1.0);
  ray.origin = glm::vec3(T_world_camera.translation);
  ray.direction = glm::vec3(d);
  const auto hit = proxy.intersect(ray);
  if (!hit || hit->back_face) return std::nullopt;
  if (std::abs(glm::dot(glm::normalize(d), glm::dvec3(hit->normal))) < 0.15) return std::nullopt;
  const glm::dvec3 p = T_world_camera.translation + double(hit->t) * d;
  return cv::Point3f(float(p.x), float(p.y), float(p.z));
}

}  // namespace lumar::pipeline
