#include "lumar/pipeline/proxy_alignment.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "pose_from_points.h"
#include "proxy_point.h"

namespace lumar::pipeline {

namespace {

// Grey levels in which the prediction and the video look alike up to a local gain and
// offset: the video is about radiance^(1/2.2) (its response), the prediction is radiance.
cv::Mat grey_of_radiance(const cv::Mat& radiance_bgr) {
  cv::Mat grey;
  cv::cvtColor(radiance_bgr, grey, cv::COLOR_BGR2GRAY);
  cv::max(grey, 0.0, grey);
  cv::pow(grey, 1.0 / 2.2, grey);
  return grey;
}

// The offset of a correlation peak from its pixel along one axis: the vertex of the
// parabola through the peak and its two neighbours.
double parabola_vertex(float before, float at, float after) {
  const double curvature = before - 2.0 * at + after;
  return curvature < 0 ? 0.5 * (before - after) / curvature : 0.0;
}

}  // namespace

ProxyAlignment::ProxyAlignment(const CameraIntrinsics& camera, const RayScene& proxy, RoomPrediction predict,
                               const ProxyAlignmentSettings& settings)
    : pinhole_(camera.without_distortion()),
      proxy_(proxy),
      predict_(std::move(predict)),
      settings_(settings),
      undistort_(calib::make_undistortion_maps(camera)) {
  if (settings.patch_px < 5 || settings.patch_px % 2 == 0 || settings.search_px < 1)
    throw InputError("proxy alignment: the patch must be odd and at least 5 px, the search at least 1 px");
}

std::optional<ProxyAlignment::Result> ProxyAlignment::align(const cv::Mat& frame, const Pose& guess) const {
  const cv::Mat predicted = grey_of_radiance(predict_(pinhole_, guess));
  cv::Mat video;
  cv::cvtColor(calib::undistort_image(frame, undistort_), video, cv::COLOR_BGR2GRAY);
  video.convertTo(video, CV_32F);

  // Corners of the prediction, far enough from the border for their whole search.
  const int half = settings_.patch_px / 2, reach = half + settings_.search_px;
  if (predicted.cols <= 2 * reach || predicted.rows <= 2 * reach) return std::nullopt;
  cv::Mat inside(predicted.size(), CV_8U, cv::Scalar(0));
  inside(cv::Rect(reach, reach, predicted.cols - 2 * reach, predicted.rows - 2 * reach)).setTo(255);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(predicted, corners, settings_.max_corners, 0.01, std::max(8, predicted.cols / 60), inside, 3);

  std::vector<cv::Point3f> points;
  std::vector<cv::Point2f> seen;
  const int side = 2 * settings_.search_px + 1;
  cv::Mat score;
  for (const cv::Point2f& corner : corners) {
    const cv::Point at(cvRound(corner.x), cvRound(corner.y));
    const cv::Mat patch = predicted(cv::Rect(at.x - half, at.y - half, settings_.patch_px, settings_.patch_px));
    const cv::Mat area = video(cv::Rect(at.x - reach, at.y - reach, settings_.patch_px + 2 * settings_.search_px,
                                        settings_.patch_px + 2 * settings_.search_px));
    cv::matchTemplate(area, patch, score, cv::TM_CCOEFF_NORMED);
    double best = 0;
    cv::Point peak;
    cv::minMaxLoc(score, nullptr, &best, nullptr, &peak);
    // A peak on the search's edge may lie beyond it.
    if (best < settings_.min_score || peak.x == 0 || peak.y == 0 || peak.x == side - 1 || peak.y == side - 1) continue;
    const float* row = score.ptr<float>(peak.y);
    const double dx = parabola_vertex(row[peak.x - 1], row[peak.x], row[peak.x + 1]);
    const double dy =
        parabola_vertex(score.at<float>(peak.y - 1, peak.x), row[peak.x], score.at<float>(peak.y + 1, peak.x));
    const cv::Point2f ray(float((at.x - pinhole_.cx) / pinhole_.fx), float((at.y - pinhole_.cy) / pinhole_.fy));
    const auto point = point_on_proxy(proxy_, guess, ray);
    if (!point) continue;
    const double u = at.x + (peak.x - settings_.search_px) + dx, v = at.y + (peak.y - settings_.search_px) + dy;
    points.push_back(*point);
    seen.emplace_back(float((u - pinhole_.cx) / pinhole_.fx), float((v - pinhole_.cy) / pinhole_.fy));
  }
  const auto solved =
      pose_from_points(points, seen, guess, settings_.ransac_px / pinhole_.fx, 200, settings_.min_inliers);
  if (!solved) return std::nullopt;
  return Result{solved->T_world_camera, static_cast<int>(seen.size()), static_cast<int>(solved->inliers.size()),
                solved->rms * pinhole_.fx};
}

}  // namespace lumar::pipeline
