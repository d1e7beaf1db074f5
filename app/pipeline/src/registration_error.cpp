#include "lumar/pipeline/registration_error.h"

#include <algorithm>
#include <cmath>

#include "lumar/base/error.h"

namespace lumar::pipeline {

double projection_error_px(const CameraIntrinsics& camera, const std::vector<glm::dvec3>& points, const Pose& pose,
                           const Pose& truth) {
  const Pose a = pose.inverse(), b = truth.inverse();
  double sum = 0;
  for (const auto& p : points)
    sum += glm::length(project_pinhole(camera, a.apply(p)) - project_pinhole(camera, b.apply(p)));
  return points.empty() ? 0.0 : sum / points.size();
}

RegistrationError registration_error(ReplayOverlay& overlay, PoseSource source) {
  if (overlay.replay().reader().truth().empty())
    throw InputError("registration error: the recording has no ground truth (truth.csv)");
  const PoseSource was = overlay.pose_source();
  overlay.set_pose_source(source);  // afresh: a fused source starts from the first frame
  RegistrationError out;
  const auto& points = overlay.compositor().object_points();
  const CameraIntrinsics& camera = overlay.compositor().output_camera();
  auto frames = overlay.replay().open_frames();
  capture::Frame frame;
  while (frames->read(frame)) {
    ++out.frames;
    overlay.overlay().play_paths(frame.time);
    const auto pose = overlay.camera_pose(frame);
    const auto truth = overlay.replay().true_camera_pose(frame.index);
    if (pose && truth) out.px.push_back(projection_error_px(camera, points, *pose, *truth));
  }
  overlay.set_pose_source(was);
  if (!out.px.empty()) {
    std::vector<double> sorted = out.px;
    std::sort(sorted.begin(), sorted.end());
    for (double e : sorted) out.mean += e / sorted.size();
    out.worst = sorted.back();
    out.p95 = sorted[std::min(sorted.size() - 1, std::size_t(std::ceil(0.95 * sorted.size())) - 1)];
  }
  return out;
}

}  // namespace lumar::pipeline
