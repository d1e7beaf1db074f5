#include "lumar/calib/calibration_report.h"

#include <algorithm>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/calib/image_file.h"

namespace lumar::calib {

void save_calibration_report(const std::filesystem::path& path, const RobustCalibrationResult& r,
                             cv::Size board_inner_corners, double square_size_m) {
  {
    // Into memory first, then onto disk whole (lumar/base/output_file.h).
    cv::FileStorage fs(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    const CameraIntrinsics& c = r.camera.intrinsics;
    fs << "nframes" << int(r.used_views.size());
    fs << "image_width" << c.width;
    fs << "image_height" << c.height;
    fs << "board_width" << board_inner_corners.width;
    fs << "board_height" << board_inner_corners.height;
    fs << "square_size" << square_size_m;
    fs << "camera_matrix" << cv::Mat(c.camera_matrix());
    fs << "distortion_coefficients" << c.distortion_coefficients();
    fs << "avg_reprojection_error" << r.camera.avg_reprojection_error;
    fs << "per_view_reprojection_errors" << cv::Mat(r.per_view_rms, true);
    fs << "std_deviations_intrinsics" << cv::Mat(std::vector<double>(r.std_dev.begin(), r.std_dev.end()), true);
    fs << "views_used"
       << "[";
    for (const auto& v : r.used_views) fs << v;
    fs << "]";
    fs << "views_rejected"
       << "[";
    for (const auto& v : r.rejected)
      fs << "{"
         << "file" << v.name << "rms" << v.rms_px << "threshold" << v.threshold_px << "round" << v.round << "}";
    fs << "]";
    fs << "views_without_board"
       << "[";
    for (const auto& v : r.views_without_board) fs << v;
    fs << "]";
    fs << "initial_reprojection_error" << r.initial_rms;
    fs << "holdout_reprojection_error" << r.holdout_rms;
    fs << "holdout_training_error" << r.training_rms;
    fs << "holdout_splits" << r.holdout_splits;
    fs << "coverage_fraction" << r.coverage;
    fs << "board_orientations" << r.orientations;
    write_file_atomically(path, fs.releaseAndGetString());
  }
}

void write_coverage_image(const std::filesystem::path& path, const BoardViews& views, const RobustCalibrationResult& r,
                          const RobustCalibrationOptions& o) {
  const cv::Size size = views.image_size;
  cv::Mat img(size, CV_8UC3, cv::Scalar(40, 40, 40));
  auto cell = [&](int x, int y) {
    return cv::Rect(cv::Point(x * size.width / o.coverage_cols, y * size.height / o.coverage_rows),
                    cv::Point((x + 1) * size.width / o.coverage_cols, (y + 1) * size.height / o.coverage_rows));
  };
  auto is_used = [&](const std::string& name) {
    return std::find(r.used_views.begin(), r.used_views.end(), name) != r.used_views.end();
  };
  // Occupied cells, as calibrate_robust counted them (kept views only).
  for (std::size_t i = 0; i < views.names.size(); ++i) {
    if (!is_used(views.names[i])) continue;
    for (const cv::Point2f& p : views.corners[i]) {
      const int x = std::clamp(int(p.x * o.coverage_cols / size.width), 0, o.coverage_cols - 1);
      const int y = std::clamp(int(p.y * o.coverage_rows / size.height), 0, o.coverage_rows - 1);
      cv::rectangle(img, cell(x, y), cv::Scalar(90, 90, 90), cv::FILLED);
    }
  }
  for (int y = 0; y < o.coverage_rows; ++y)
    for (int x = 0; x < o.coverage_cols; ++x) cv::rectangle(img, cell(x, y), cv::Scalar(120, 120, 120), 1);
  const int n = int(views.names.size());
  for (int i = 0; i < n; ++i) {
    const bool used = is_used(views.names[i]);
    cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(180 * i / std::max(n, 1), 220, 255)), bgr;
    cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b colour = bgr.at<cv::Vec3b>(0, 0);
    for (const cv::Point2f& p : views.corners[i]) {
      const cv::Point q(cvRound(p.x), cvRound(p.y));
      if (used)
        cv::circle(img, q, 3, cv::Scalar(colour[0], colour[1], colour[2]), cv::FILLED, cv::LINE_AA);
      else
        cv::drawMarker(img, q, cv::Scalar(160, 160, 160), cv::MARKER_CROSS, 7, 1);
    }
  }
  char caption[96];
  std::snprintf(caption, sizeof caption, "coverage %.0f%%, %zu views kept, %zu rejected", 100 * r.coverage,
                r.used_views.size(), r.rejected.size());
  cv::putText(img, caption, {8, size.height - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);

  write_image_atomically(path, img);
}

}  // namespace lumar::calib
