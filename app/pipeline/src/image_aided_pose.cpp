#include "lumar/pipeline/image_aided_pose.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/board_pose.h"
#include "pose_from_points.h"
#include "proxy_point.h"

namespace lumar::pipeline {

namespace {

constexpr std::int64_t kMaxDroppedFrames = 30;
// A live source skips the frames the overlay is too slow for, a few at a time: over such
// gaps the corners still track, so the fused pose keeps its worth.
constexpr std::int64_t kSkippedFrames = 4;

// Corners in pixels to points on the normalised image plane (distortion removed).
std::vector<cv::Point2f> normalised(const CameraIntrinsics& camera, const std::vector<cv::Point2f>& pixels) {
  std::vector<cv::Point2f> out;
  if (!pixels.empty())
    cv::undistortPoints(pixels, out, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients());
  return out;
}

}  // namespace

ImageAidedPose::ImageAidedPose(const CameraIntrinsics& camera, const Mesh& proxy, const ImageAidedSettings& settings,
                               RoomPrediction predict)
    : camera_(camera), settings_(settings), fusion_(settings.fusion) {
  if (proxy.triangle_count() == 0)
    throw InputError("image-aided tracking needs the scene's proxy room: its corners' depth comes from it");
  if (settings.align_every < 0)
    throw InputError("--align-every: the frames between absolute fixes must be >= 0, not " +
                     std::to_string(settings.align_every));
  proxy_.add_static(proxy);
  proxy_.commit();
  if (predict && settings.fusion.fix_worth > 0)
    alignment_.emplace(camera, proxy_, std::move(predict), settings.alignment);
}

std::optional<Pose> ImageAidedPose::update(const capture::Frame& frame, const std::optional<Pose>& tracker) {
  if (frame.index == last_index_) return last_fused_;
  // After a seek the fused pose starts again from the tracker. Over dropped frames the
  // corners are looked for where the tracker's motion since the last frame puts them.
  if (frame.index <= last_index_ || frame.index > last_index_ + kMaxDroppedFrames) {
    fusion_.reset();
    corners_.clear();
    points_.clear();
    fix_due_ = true;
  } else if (frame.index > last_index_ + 1 + kSkippedFrames) {
    fusion_.restart_mean();
    fix_due_ = true;
  } else if (frame.index > last_index_ + 1) {
    fusion_.forget_motion();  // the video's last motion spans several frames
  }
  cv::Mat grey;
  cv::cvtColor(frame.image, grey, cv::COLOR_BGR2GRAY);
  std::optional<Pose> visual;
  tracked_.clear();
  if (fusion_.pose() && !corners_.empty()) visual = pose_from_video(grey, *fusion_.pose(), tracker);
  last_fused_ = fusion_.update(visual, tracker);
  ++frames_since_fix_try_;
  if (last_fused_ && alignment_ &&
      (fix_due_ || (settings_.align_every > 0 && frames_since_fix_try_ >= settings_.align_every)))
    try_fix(frame.image);
  ++stats_.frames;
  if (last_fused_)
    anchor(grey, *last_fused_);
  else
    corners_.clear(), points_.clear();
  last_grey_ = grey;
  last_index_ = frame.index;
  if (tracker) last_tracker_ = tracker;
  return last_fused_;
}

std::optional<Pose> ImageAidedPose::pose_from_video(const cv::Mat& grey, const Pose& last,
                                                    const std::optional<Pose>& tracker) {
  // Start from the last pose moved as the tracker moved: each corner is looked for where
  // its point projects from there, and PnP is refined from there.
  Pose guess = last;
  if (tracker && last_tracker_) guess = last * (last_tracker_->inverse() * *tracker);
  cv::Vec3d rvec, tvec;
  calib::pose_to_rvec_tvec(guess.inverse(), rvec, tvec);  // OpenCV's pose is T_camera_world
  std::vector<cv::Point2f> ahead, back;
  cv::projectPoints(points_, rvec, tvec, cv::Mat(camera_.camera_matrix()), camera_.distortion_coefficients(), ahead);
  std::vector<std::uint8_t> ok_ahead, ok_back;
  std::vector<float> err;
  const cv::Size window(21, 21);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  cv::calcOpticalFlowPyrLK(last_grey_, grey, corners_, ahead, ok_ahead, err, window, 3, stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW, settings_.min_eigen);
  cv::calcOpticalFlowPyrLK(grey, last_grey_, ahead, back, ok_back, err, window, 3);
  std::vector<cv::Point2f> seen;
  std::vector<cv::Point3f> points;
  for (std::size_t i = 0; i < corners_.size(); ++i) {
    const cv::Point2f d = back[i] - corners_[i];
    if (ok_ahead[i] && ok_back[i] && d.dot(d) < 0.25f && ahead[i].x >= 0 && ahead[i].y >= 0 && ahead[i].x < grey.cols &&
        ahead[i].y < grey.rows) {
      seen.push_back(ahead[i]);
      points.push_back(points_[i]);
    }
  }
  const auto solved = pose_from_points(points, normalised(camera_, seen), guess, settings_.ransac_px / camera_.fx, 100,
                                       settings_.min_inliers);
  if (!solved || rotation_angle_deg(solved->T_world_camera.rotation, guess.rotation) > settings_.max_disagree_deg)
    return std::nullopt;
  const std::vector<int>& inliers = solved->inliers;
  for (int i : inliers) tracked_.push_back(seen[i]);
  stats_.inliers += (inliers.size() - stats_.inliers) / (++stats_.visual_frames);
  return solved->T_world_camera;
}

void ImageAidedPose::try_fix(const cv::Mat& image) {
  frames_since_fix_try_ = 0;
  fix_due_ = false;
  ++stats_.fix_attempts;
  const auto fix = alignment_->align(image, *last_fused_);
  if (!fix || rotation_angle_deg(fix->T_world_camera.rotation, last_fused_->rotation) > settings_.max_fix_offset_deg ||
      glm::length(fix->T_world_camera.translation - last_fused_->translation) > settings_.max_fix_offset_m)
    return;
  ++stats_.fixes;
  last_fused_ = fusion_.fix(fix->T_world_camera);
}

void ImageAidedPose::anchor(const cv::Mat& grey, const Pose& fused) {
  std::vector<cv::Point2f> corners = tracked_;
  // Fresh corners where the tracked ones have thinned out, away from those still held.
  if (static_cast<int>(corners.size()) < settings_.max_corners * 2 / 3) {
    const int spacing = std::max(8, grey.cols / 60);
    cv::Mat free_area(grey.size(), CV_8U, cv::Scalar(255));
    for (const auto& c : corners) cv::circle(free_area, c, spacing, cv::Scalar(0), -1);
    std::vector<cv::Point2f> fresh;
    cv::goodFeaturesToTrack(grey, fresh, settings_.max_corners - static_cast<int>(corners.size()), 0.01, spacing,
                            free_area, 3);
    corners.insert(corners.end(), fresh.begin(), fresh.end());
  }
  const std::vector<cv::Point2f> rays = normalised(camera_, corners);
  corners_.clear();
  points_.clear();
  for (std::size_t i = 0; i < corners.size(); ++i)
    if (const auto point = point_on_proxy(proxy_, fused, rays[i])) {
      corners_.push_back(corners[i]);
      points_.push_back(*point);
    }
}

}  // namespace lumar::pipeline
