#include "lumar/sim/truth_frame.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace lumar::sim {

namespace {

struct PixelRay {
  glm::dvec3 origin, direction;
};

PixelRay pixel_ray(const CameraIntrinsics& camera, const Pose& T_world_camera, double c, double r) {
  const glm::dvec3 d((c - camera.cx) / camera.fx, (r - camera.cy) / camera.fy, 1.0);
  return {T_world_camera.translation, glm::normalize(T_world_camera.rotation * d)};
}

// Where a pixel's ray meets the room's surfaces, with the hit's normal.
struct RoomPoint {
  glm::dvec3 point, normal;
  double t;
};

std::optional<RoomPoint> room_point(const RayScene& room_surfaces, const PixelRay& ray) {
  Ray r;
  r.origin = glm::vec3(ray.origin);
  r.direction = glm::vec3(ray.direction);
  const auto hit = room_surfaces.intersect(r);
  if (!hit) return std::nullopt;
  return RoomPoint{ray.origin + ray.direction * double(hit->t), glm::dvec3(hit->normal), double(hit->t)};
}

}  // namespace

TruthFrame render_truth_frame(const CompositeReference& reference, const RayScene& room_surfaces,
                              const CameraIntrinsics& camera, const Pose& T_world_camera, const cv::Mat& empty_radiance,
                              const TruthSettings& settings) {
  CV_Assert(empty_radiance.type() == CV_32FC3 && empty_radiance.cols == camera.width &&
            empty_radiance.rows == camera.height);
  const int W = camera.width, H = camera.height, s = std::max(1, settings.ratio_stride);
  // The room's ratio on a grid of nodes every s pixels (the last beyond the image edge
  // if need be), each at the proxy point its ray meets, whatever hides that point.
  const int gw = (W - 1) / s + 2, gh = (H - 1) / s + 2;
  std::vector<glm::vec3> grid(std::size_t(gw) * gh, glm::vec3(1.0f));
  tbb::parallel_for(0, gh, [&](int j) {
    for (int i = 0; i < gw; ++i) {
      const auto room = room_point(room_surfaces, pixel_ray(camera, T_world_camera, double(i * s), double(j * s)));
      if (room) grid[std::size_t(j) * gw + i] = glm::vec3(reference.room_ratio(room->point, room->normal));
    }
  });
  TruthFrame out;
  out.radiance = empty_radiance.clone();
  out.coverage = cv::Mat::zeros(H, W, CV_32FC1);
  tbb::parallel_for(0, H, [&](int r) {
    auto* pixel = out.radiance.ptr<cv::Vec3f>(r);
    auto* covered = out.coverage.ptr<float>(r);
    for (int c = 0; c < W; ++c) {
      const PixelRay ray = pixel_ray(camera, T_world_camera, c, r);
      const auto room = room_point(room_surfaces, ray);
      const auto object =
          reference.hit_object(ray.origin, ray.direction, room ? room->t : std::numeric_limits<double>::infinity());
      if (object) {
        const glm::dvec3 L = reference.object_radiance(*object, settings.per_pixel_objects);
        pixel[c] = cv::Vec3f(float(L.b), float(L.g), float(L.r));
        covered[c] = 1.0f;
        continue;
      }
      if (!room) continue;
      glm::vec3 ratio;
      if (s == 1) {
        ratio = grid[std::size_t(r) * gw + c];
      } else {
        const int i = c / s, j = r / s;
        const float u = float(c - i * s) / float(s), v = float(r - j * s) / float(s);
        const auto at = [&](int di, int dj) { return grid[std::size_t(j + dj) * gw + i + di]; };
        ratio = (1 - v) * ((1 - u) * at(0, 0) + u * at(1, 0)) + v * ((1 - u) * at(0, 1) + u * at(1, 1));
      }
      pixel[c] = cv::Vec3f(pixel[c][0] * ratio.b, pixel[c][1] * ratio.g, pixel[c][2] * ratio.r);
    }
  });
  return out;
}

}  // namespace lumar::sim
