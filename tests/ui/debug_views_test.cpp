// The debug views land where the geometry projects: the proxy's edges (checked against
// cv::projectPoints), the receivers, and nothing at all when every view is off.
#include "lumar/ui/debug_views.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/capture/recording_replay.h"
#include "lumar/render/platform/context.h"
#include "lumar/scene/loaded_scene.h"
#include "test_paths.h"

namespace lumar {
namespace {

TEST(DebugViews, DrawnWhereTheGeometryProjects) {
  auto context = gl::create_headless_context();
  const capture::RecordingReplay replay(test::source_dir() / "recordings/orbit");
  const Pose pose = *replay.true_camera_pose(15);
  const CameraIntrinsics camera = replay.session().camera.without_distortion();
  auto scene =
      std::make_shared<const LoadedScene>(load_scene_files(test::source_dir() / "data/scenes/room/scene.json"));
  Compositor compositor(scene, camera, cv::Mat(), cv::Mat());
  const cv::Mat black(camera.height, camera.width, CV_8UC3, cv::Scalar(0, 0, 0));

  EXPECT_EQ(cv::countNonZero(ui::draw_debug_views(black, compositor, pose, {}).reshape(1)), 0);

  // Every proxy edge whose middle is in view: a drawn pixel within 1.5 px of where
  // OpenCV projects that middle.
  const cv::Mat wire = ui::draw_debug_views(black, compositor, pose, {.proxy_wireframe = true});
  cv::Mat drawn;
  cv::cvtColor(wire, drawn, cv::COLOR_BGR2GRAY);
  const Pose T_camera_world = pose.inverse();
  const Mesh& room = scene->room;
  int checked = 0;
  for (std::size_t t = 0; t + 2 < room.indices.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const glm::dvec3 mid = 0.5 * (glm::dvec3(room.positions[room.indices[t + e]]) +
                                    glm::dvec3(room.positions[room.indices[t + (e + 1) % 3]]));
      const glm::dvec3 c = T_camera_world.apply(mid);
      if (c.z < 0.1) continue;
      std::vector<cv::Point2d> px;
      cv::projectPoints(std::vector<cv::Point3d>{{c.x, c.y, c.z}}, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                        cv::Mat(camera.camera_matrix()), cv::noArray(), px);
      const cv::Rect near(int(std::round(px[0].x)) - 1, int(std::round(px[0].y)) - 1, 3, 3);
      if ((near & cv::Rect(0, 0, camera.width, camera.height)) != near) continue;
      EXPECT_GT(cv::countNonZero(drawn(near)), 0) << "edge middle at " << px[0];
      ++checked;
    }
  EXPECT_GE(checked, 4);

  // Receivers: as many dots as receivers in view, in the lit colour (no shadow computed yet).
  const cv::Mat dots = ui::draw_debug_views(black, compositor, pose, {.receivers = true});
  cv::Mat green;
  cv::inRange(dots, cv::Scalar(0, 200, 0), cv::Scalar(0, 255, 0), green);
  EXPECT_GT(cv::countNonZero(green), 100);
}

}  // namespace
}  // namespace lumar
