#include "lumar/ui/object_placement.h"

#include <glm/gtc/matrix_transform.hpp>

namespace lumar::ui {

Ray pixel_ray(const CameraIntrinsics& pinhole, const Pose& T_world_camera, const glm::dvec2& pixel) {
  const glm::dvec3 d_camera((pixel.x - pinhole.cx) / pinhole.fx, (pixel.y - pinhole.cy) / pinhole.fy, 1.0);
  Ray ray;
  ray.origin = glm::vec3(T_world_camera.translation);
  ray.direction = glm::vec3(T_world_camera.rotation * d_camera);
  return ray;
}

std::optional<SurfacePoint> surface_at_pixel(const RayScene& proxy, const CameraIntrinsics& pinhole,
                                             const Pose& T_world_camera, const glm::dvec2& pixel) {
  const Ray ray = pixel_ray(pinhole, T_world_camera, pixel);
  const auto hit = proxy.intersect(ray);
  if (!hit || hit->back_face) return std::nullopt;  // nothing, or the camera is inside geometry
  // The point in double precision along the ray (float t, but a few metres at most).
  const glm::dvec3 origin = T_world_camera.translation;
  const glm::dvec3 direction = T_world_camera.rotation * glm::dvec3((pixel.x - pinhole.cx) / pinhole.fx,
                                                                    (pixel.y - pinhole.cy) / pinhole.fy, 1.0);
  return SurfacePoint{origin + double(hit->t) * direction, glm::normalize(glm::dvec3(hit->normal))};
}

glm::dmat4 rest_on_surface(const Mesh& model, const glm::dmat3& linear, const SurfacePoint& at) {
  // A frame on the surface: two tangents and the normal.
  const glm::dvec3 n = glm::normalize(at.normal);
  const glm::dvec3 helper = std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  const glm::dvec3 t1 = glm::normalize(glm::cross(helper, n)), t2 = glm::cross(n, t1);
  glm::dvec3 lo(1e300), hi(-1e300);  // extent along t1, t2, n
  for (const glm::vec3& p : model.positions) {
    const glm::dvec3 w = linear * glm::dvec3(p);
    const glm::dvec3 c(glm::dot(w, t1), glm::dot(w, t2), glm::dot(w, n));
    lo = glm::min(lo, c), hi = glm::max(hi, c);
  }
  const glm::dvec3 footprint_centre = 0.5 * (lo.x + hi.x) * t1 + 0.5 * (lo.y + hi.y) * t2 + lo.z * n;
  glm::dmat4 T(linear);
  T[3] = glm::dvec4(at.point - footprint_centre, 1.0);
  return T;
}

glm::dmat4 turn_on_surface(const glm::dmat4& T_world_model, const SurfacePoint& at, double degrees) {
  return glm::translate(glm::dmat4(1.0), at.point) * glm::rotate(glm::dmat4(1.0), glm::radians(degrees), at.normal) *
         glm::translate(glm::dmat4(1.0), -at.point) * T_world_model;
}

}  // namespace lumar::ui
