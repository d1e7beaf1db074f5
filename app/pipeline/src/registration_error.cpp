#include "lumar/pipeline/registration_error.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

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
  // Per frame with both poses: time, offset, where the truth projects, whether still.
  std::vector<double> time;
  std::vector<glm::dvec2> offset;
  std::vector<glm::dvec3> centre;  // of the points
  std::vector<Pose> truths;
  std::vector<bool> still;
  std::optional<Pose> last_truth;
  while (frames->read(frame)) {
    ++out.frames;
    overlay.overlay().play_paths(frame.time);
    const auto t0 = std::chrono::steady_clock::now();
    const auto pose = overlay.camera_pose(frame);
    out.pose_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const auto truth = overlay.replay().true_camera_pose(frame.index);
    if (!pose || !truth) continue;
    out.px.push_back(projection_error_px(camera, points, *pose, *truth));
    const Pose a = pose->inverse(), b = truth->inverse();
    glm::dvec2 d(0.0);
    glm::dvec3 c(0.0);
    for (const auto& x : points) d += project_pinhole(camera, a.apply(x)) - project_pinhole(camera, b.apply(x)), c += x;
    const double n = std::max<std::size_t>(1, points.size());
    time.push_back(nanos_to_seconds(frame.time));
    offset.push_back(d / n), centre.push_back(c / n), truths.push_back(*truth);
    still.push_back(last_truth && rotation_angle_deg(last_truth->rotation, truth->rotation) < 1e-3 &&
                    glm::distance(last_truth->translation, truth->translation) < 1e-5);
    last_truth = truth;
  }
  overlay.set_pose_source(was);
  if (out.frames > 0) out.pose_ms /= out.frames;

  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.jitter_px = out.lag_ms = out.overshoot_px = nan;
  const std::size_t m = time.size();
  // Jitter: each still stretch about its own mean.
  double sum2 = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < m;) {
    if (!still[i]) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < m && still[j]) ++j;
    std::vector<glm::dvec2> kept;
    for (std::size_t k = i; k < j; ++k)
      if (time[k] - time[0] >= 1.0 && time[k] - time[i] >= 0.5) kept.push_back(offset[k]);
    if (kept.size() >= 2) {
      glm::dvec2 mean(0.0);
      for (const auto& o : kept) mean += o / double(kept.size());
      for (const auto& o : kept) sum2 += glm::dot(o - mean, o - mean), ++count;
    }
    i = j;
  }
  if (count > 0) out.jitter_px = std::sqrt(sum2 / count);
  // Lag and overshoot: the image velocity the camera's true motion gives the points'
  // centre (not the objects' own motion), by central differences.
  double dv = 0, vv = 0;
  glm::dvec2 last_motion(0.0);
  double stopped_at = -1;
  for (std::size_t k = 1; k + 1 < m; ++k) {
    const auto at = [&](std::size_t j) { return project_pinhole(camera, truths[j].inverse().apply(centre[k])); };
    const glm::dvec2 v = (at(k + 1) - at(k - 1)) / (time[k + 1] - time[k - 1]);
    if (glm::length(v) > 20.0) {
      dv += glm::dot(offset[k], v), vv += glm::dot(v, v);
      last_motion = glm::normalize(v), stopped_at = -1;
    } else if (glm::length(last_motion) > 0) {
      if (stopped_at < 0) stopped_at = time[k];
      if (time[k] - stopped_at <= 0.5)
        out.overshoot_px =
            std::max(std::isnan(out.overshoot_px) ? 0.0 : out.overshoot_px, glm::dot(offset[k], last_motion));
    }
  }
  if (vv > 0) out.lag_ms = -1e3 * dv / vv;
  for (std::size_t k = 1; k < m; ++k) out.jump_px = std::max(out.jump_px, glm::length(offset[k] - offset[k - 1]));
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
