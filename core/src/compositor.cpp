#include "lumar/core/compositor.h"

#include <spdlog/spdlog.h>

#include "lumar/core/envmap.h"
#include "lumar/core/mesh.h"

namespace lumar {

Compositor::Compositor(const Scene& scene, const CameraIntrinsics& output_camera, const cv::Mat& map_x,
                       const cv::Mat& map_y)
    : camera_(output_camera.without_distortion()) {
  EnvironmentMap map = load_environment_map(scene.environment_map);
  map.capture_position = scene.capture_position;
  map.azimuth_offset_deg = scene.azimuth_offset_deg;
  sh_ = project_radiance_sh9(map);

  renderer_ = std::make_unique<gl::Renderer>(camera_);
  if (!scene.room_mesh.empty()) {
    const double s = scene.room_scale;
    renderer_->set_room(transformed(load_mesh(scene.room_mesh), glm::dmat4(glm::dmat3(s))));
  }
  renderer_->set_environment(map);
  if (!map_x.empty()) renderer_->set_undistortion_map(map_x, map_y);

  for (const SceneObject& object : scene.objects) {
    const Mesh mesh = load_mesh(object.mesh);
    const int id = renderer_->add_object(mesh);
    renderer_->set_object_pose(id, object.T_world_model);
    renderer_->set_object_material(id, object.albedo, sh_);
    // Every k-th vertex, so that checks see the whole object at a bounded cost.
    const std::size_t step = std::max<std::size_t>(1, mesh.positions.size() / 200);
    for (std::size_t i = 0; i < mesh.positions.size(); i += step)
      object_points_.push_back(glm::dvec3(object.T_world_model * glm::dvec4(glm::dvec3(mesh.positions[i]), 1.0)));
    spdlog::debug("object '{}': {} triangles", object.name, mesh.triangle_count());
  }
}

cv::Mat Compositor::composite(const cv::Mat& video_bgr8, const std::optional<Pose>& T_world_camera, double exposure,
                              gl::OverlayTimings* timings) {
  return renderer_->render_overlay(video_bgr8, T_world_camera, exposure, timings);
}

}  // namespace lumar
