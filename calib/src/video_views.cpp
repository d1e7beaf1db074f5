#include "lumar/calib/video_views.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "lumar/core/error.h"

namespace lumar::calib {

std::vector<NamedImage> sample_frames(capture::FrameSource& source, int every, int max_frames) {
  if (every < 1) throw InputError("--every: must be 1 or more");
  std::vector<NamedImage> out;
  capture::Frame frame;
  for (int k = 0; int(out.size()) < max_frames && source.read(frame); ++k)
    if (k % every == 0) out.push_back({source.describe() + "#" + std::to_string(frame.index), frame.image.clone()});
  if (out.empty()) throw InputError(source.describe() + ": delivered no frames");
  return out;
}

CheckerboardViews detect_checkerboard_views(const std::vector<NamedImage>& images, cv::Size inner_corners,
                                            double square_size_m) {
  const std::string size_text = std::to_string(inner_corners.width) + "x" + std::to_string(inner_corners.height);
  if (images.empty()) throw InputError("checkerboard calibration: no images given");
  if (inner_corners.width < 2 || inner_corners.height < 2)
    throw InputError("checkerboard calibration: board size " + size_text + " is too small; give the inner corners");
  if (!(square_size_m > 0.0) || !std::isfinite(square_size_m))
    throw InputError("checkerboard calibration: square size must be a positive length in metres");
  CheckerboardViews result;
  result.board = checkerboard_points(inner_corners, square_size_m);
  result.image_size = images.front().image.size();
  for (const auto& named : images) {
    if (named.image.size() != result.image_size)
      throw InputError(named.name + ": image size differs from " + images.front().name + "; calibrate one camera mode at a time");
    cv::Mat gray;
    if (named.image.channels() == 3)
      cv::cvtColor(named.image, gray, cv::COLOR_BGR2GRAY);
    else
      gray = named.image;
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(gray, inner_corners, corners, cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK) &&
        !(result.names.size() > 0 &&
          cv::findChessboardCorners(gray, inner_corners, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_FAST_CHECK))) {
      result.views_without_board.push_back(named.name);
      continue;
    }
    // Half the neighbouring corners' spacing, at most 11 px (as board_pose.cpp).
    double spacing = 1e9;
    for (std::size_t i = 0; i + 1 < corners.size(); ++i)
      if ((i + 1) % std::size_t(inner_corners.width) != 0)
        spacing = std::min(spacing, double(cv::norm(corners[i + 1] - corners[i])));
    const int half = std::clamp(int(spacing * 0.5), 3, 11);
    cv::cornerSubPix(gray, corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.0001));
    result.corners.push_back(std::move(corners));
    result.names.push_back(named.name);
  }
  if (result.corners.empty())
    throw InputError("checkerboard calibration: no " + size_text + " inner-corner board found in any of the " +
                     std::to_string(images.size()) + " images; check the board size (inner corners, not squares)");
  if (result.corners.size() < 3)
    throw InputError("checkerboard calibration: the board was found in only " + std::to_string(result.corners.size()) +
                     " image(s); at least 3 views are needed");
  return result;
}

}  // namespace lumar::calib
