#include "lumar/ui/debug_views.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"

namespace lumar::ui {

namespace {

constexpr double kNear = 0.05;  // metres in front of the camera

struct Projector {
  const CameraIntrinsics& camera;
  Pose T_camera_world;
  glm::dvec3 to_camera(const glm::dvec3& p) const { return T_camera_world.apply(p); }
  cv::Point2d pixel(const glm::dvec3& c) const {
    return {camera.fx * c.x / c.z + camera.cx, camera.fy * c.y / c.z + camera.cy};
  }
  std::optional<cv::Point2d> project(const glm::dvec3& p) const {
    const glm::dvec3 c = to_camera(p);
    if (c.z < kNear) return std::nullopt;
    return pixel(c);
  }
  // A world segment, cut where it passes behind the near plane.
  void line(cv::Mat& image, glm::dvec3 a, glm::dvec3 b, const cv::Scalar& colour) const {
    glm::dvec3 ca = to_camera(a), cb = to_camera(b);
    if (ca.z < kNear && cb.z < kNear) return;
    if (ca.z < kNear) ca = glm::mix(ca, cb, (kNear - ca.z) / (cb.z - ca.z));
    if (cb.z < kNear) cb = glm::mix(cb, ca, (kNear - cb.z) / (ca.z - cb.z));
    const cv::Point2d da = pixel(ca), db = pixel(cb);
    cv::Point2l pa(std::llround(da.x), std::llround(da.y)), pb(std::llround(db.x), std::llround(db.y));
    if (cv::clipLine(cv::Size2l(image.cols, image.rows), pa, pb))
      cv::line(image, cv::Point(int(pa.x), int(pa.y)), cv::Point(int(pb.x), int(pb.y)), colour, 1, cv::LINE_AA);
  }
};

bool inside(const cv::Mat& image, const cv::Point2d& p) {
  return p.x >= 0 && p.y >= 0 && p.x < image.cols && p.y < image.rows;
}

}  // namespace

cv::Mat draw_debug_views(const cv::Mat& composite, const Compositor& compositor, const Pose& T_world_camera,
                         const DebugViews& views) {
  cv::Mat image = composite.clone();
  const Projector projector{compositor.output_camera(), T_world_camera.inverse()};
  if (views.proxy_wireframe) {
    const Mesh& room = compositor.scene().room;
    for (std::size_t t = 0; t + 2 < room.indices.size(); t += 3)
      for (int e = 0; e < 3; ++e)
        projector.line(image, glm::dvec3(room.positions[room.indices[t + e]]),
                       glm::dvec3(room.positions[room.indices[t + (e + 1) % 3]]), cv::Scalar(255, 255, 0));
  }
  if (const LineShadows* shadows = compositor.shadows()) {
    const ShadowLines& lines = shadows->lines();
    if (views.receivers)
      for (std::size_t i = 0; i < lines.origins.size(); ++i)
        if (const auto p = projector.project(glm::dvec3(lines.origins[i])); p && inside(image, *p)) {
          const glm::vec3 a = shadows->attenuation()[i];
          const double lit = std::clamp((a.x + a.y + a.z) / 3.0, 0.0, 1.0);
          cv::circle(image, *p, 2, cv::Scalar(0, 255 * lit, 255 * (1 - lit)), cv::FILLED);
        }
    if (views.emitters && !lines.samples.empty()) {
      float brightest = 0;
      for (const EmitterPoint& s : lines.samples) brightest = std::max(brightest, s.flux.x + s.flux.y + s.flux.z);
      for (const EmitterPoint& s : lines.samples) {
        // A distant map's samples are directions: drawn 20 m away.
        const glm::dvec3 at =
            lines.distant ? T_world_camera.translation + 20.0 * glm::dvec3(s.position) : glm::dvec3(s.position);
        if (const auto p = projector.project(at); p && inside(image, *p)) {
          const double share = brightest > 0 ? (s.flux.x + s.flux.y + s.flux.z) / brightest : 0.0;
          cv::circle(image, *p, 2 + int(4 * share), cv::Scalar(0, 220, 255), 1, cv::LINE_AA);
        }
      }
    }
  }
  if (const IrradianceVolume* volume = compositor.irradiance_volume().get(); views.probes && volume) {
    std::vector<double> light;
    double brightest = 0;
    for (const glm::vec4& probe : volume->probes) {
      const glm::dvec3 e = volume->evaluate(glm::dvec3(probe), glm::dvec3(0, 1, 0));
      light.push_back((e.x + e.y + e.z) / 3.0);
      brightest = std::max(brightest, light.back());
    }
    for (std::size_t i = 0; i < volume->probes.size(); ++i)
      if (const auto p = projector.project(glm::dvec3(volume->probes[i])); p && inside(image, *p)) {
        if (volume->probes[i].w == 0) {  // disabled (inside geometry)
          cv::drawMarker(image, *p, cv::Scalar(90, 90, 90), cv::MARKER_TILTED_CROSS, 6);
          continue;
        }
        const double level = brightest > 0 ? 255.0 * light[i] / brightest : 0.0;
        cv::circle(image, *p, 4, cv::Scalar(level, level, level), cv::FILLED, cv::LINE_AA);
        cv::circle(image, *p, 4, cv::Scalar(255, 0, 255), 1, cv::LINE_AA);
      }
  }
  return image;
}

}  // namespace lumar::ui
