#include "lumar/calib/calibration_report.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
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

namespace {

void text(cv::Mat& img, const std::string& s, cv::Point at, double scale = 0.45,
          cv::Scalar colour = cv::Scalar(235, 235, 235)) {
  cv::putText(img, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// Where on the sensor a grid cell lies, in words ("top left", "middle", "bottom right").
std::string region_name(int x, int y, int cols, int rows) {
  const char* v = y < rows / 3 ? "top" : (y >= rows - rows / 3 ? "bottom" : "middle");
  const char* h = x < cols / 3 ? "left" : (x >= cols - cols / 3 ? "right" : "centre");
  if (std::string(v) == "middle" && std::string(h) == "centre") return "centre";
  return std::string(v) + " " + h;
}

}  // namespace

void write_coverage_image(const std::filesystem::path& path, const BoardViews& views, const RobustCalibrationResult& r,
                          const RobustCalibrationOptions& o) {
  const cv::Size size = views.image_size;
  const int legend = 74;  // rows below the sensor for the caption and the legend
  cv::Mat canvas(size.height + legend, size.width, CV_8UC3, cv::Scalar(24, 24, 24));
  cv::Mat img = canvas(cv::Rect(0, 0, size.width, size.height));
  img.setTo(cv::Scalar(40, 40, 40));
  auto cell = [&](int x, int y) {
    return cv::Rect(cv::Point(x * size.width / o.coverage_cols, y * size.height / o.coverage_rows),
                    cv::Point((x + 1) * size.width / o.coverage_cols, (y + 1) * size.height / o.coverage_rows));
  };
  auto is_used = [&](const std::string& name) {
    return std::find(r.used_views.begin(), r.used_views.end(), name) != r.used_views.end();
  };
  // Occupied cells, as calibrate_robust counted them (kept views only).
  std::vector<char> occupied(std::size_t(o.coverage_cols * o.coverage_rows), 0);
  for (std::size_t i = 0; i < views.names.size(); ++i) {
    if (!is_used(views.names[i])) continue;
    for (const cv::Point2f& p : views.corners[i]) {
      const int x = std::clamp(int(p.x * o.coverage_cols / size.width), 0, o.coverage_cols - 1);
      const int y = std::clamp(int(p.y * o.coverage_rows / size.height), 0, o.coverage_rows - 1);
      occupied[std::size_t(y * o.coverage_cols + x)] = 1;
    }
  }
  // Empty cells are hatched in red: that is where the next views should put the board.
  std::vector<std::string> missing;
  for (int y = 0; y < o.coverage_rows; ++y)
    for (int x = 0; x < o.coverage_cols; ++x) {
      const cv::Rect c = cell(x, y);
      if (occupied[std::size_t(y * o.coverage_cols + x)]) {
        cv::rectangle(img, c, cv::Scalar(90, 90, 90), cv::FILLED);
      } else {
        cv::Mat roi = img(c);
        for (int k = -c.height; k < c.width; k += 10)
          cv::line(roi, {k, c.height}, {k + c.height, 0}, cv::Scalar(40, 40, 150), 1, cv::LINE_AA);
        const std::string where = region_name(x, y, o.coverage_cols, o.coverage_rows);
        if (std::find(missing.begin(), missing.end(), where) == missing.end()) missing.push_back(where);
      }
      cv::rectangle(img, c, cv::Scalar(120, 120, 120), 1);
    }
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
  char caption[128];
  std::snprintf(caption, sizeof caption, "coverage %.0f%% of the %dx%d grid, %zu views kept, %zu rejected",
                100 * r.coverage, o.coverage_cols, o.coverage_rows, r.used_views.size(), r.rejected.size());
  const int y0 = size.height;
  text(canvas, caption, {8, y0 + 18}, 0.5);
  // Legend: a dot per corner of a kept view (one colour per view), a grey cross per
  // corner of a rejected view, a grey cell holds corners, a red-hatched one none yet.
  cv::circle(canvas, {14, y0 + 38}, 4, cv::Scalar(60, 200, 255), cv::FILLED, cv::LINE_AA);
  text(canvas, "corner of a kept view", {24, y0 + 42});
  cv::drawMarker(canvas, {204, y0 + 38}, cv::Scalar(160, 160, 160), cv::MARKER_CROSS, 9, 1);
  text(canvas, "rejected view", {214, y0 + 42});
  cv::rectangle(canvas, cv::Rect(334, y0 + 31, 14, 14), cv::Scalar(90, 90, 90), cv::FILLED);
  text(canvas, "has corners", {354, y0 + 42});
  cv::Rect hatch(454, y0 + 31, 14, 14);
  cv::rectangle(canvas, hatch, cv::Scalar(40, 40, 40), cv::FILLED);
  cv::line(canvas, {hatch.x, hatch.y + 14}, {hatch.x + 14, hatch.y}, cv::Scalar(40, 40, 150), 1, cv::LINE_AA);
  text(canvas, "no corners yet", {474, y0 + 42});
  std::string hint = missing.empty() ? "every part of the sensor has corners" : "add views with the board at: ";
  for (std::size_t i = 0; i < missing.size(); ++i) hint += (i ? ", " : "") + missing[i];
  text(canvas, hint, {8, y0 + 64}, 0.45, missing.empty() ? cv::Scalar(160, 230, 160) : cv::Scalar(140, 140, 255));
  write_image_atomically(path, canvas);
}

void write_undistorted_preview(const std::filesystem::path& path, const std::vector<NamedImage>& images,
                               const BoardViews& views, const RobustCalibrationResult& r) {
  const CameraIntrinsics& camera = r.camera.intrinsics;
  // The kept view whose corners reach farthest from the principal point: the one the
  // lens bends most.
  int best = -1;
  double reach = -1;
  for (std::size_t i = 0; i < views.names.size(); ++i) {
    if (std::find(r.used_views.begin(), r.used_views.end(), views.names[i]) == r.used_views.end()) continue;
    for (const cv::Point2f& p : views.corners[i]) {
      const double d = std::hypot(p.x - camera.cx, p.y - camera.cy);
      if (d > reach) reach = d, best = int(i);
    }
  }
  if (best < 0) return;
  const auto it = std::find_if(images.begin(), images.end(),
                               [&](const NamedImage& n) { return n.name == views.names[std::size_t(best)]; });
  if (it == images.end()) return;
  cv::Mat original = it->image.clone();
  if (original.channels() == 1) cv::cvtColor(original, original, cv::COLOR_GRAY2BGR);
  cv::Mat undistorted;
  cv::undistort(original, undistorted, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients());
  // Each row of the board's corners, undistorted, with the straight line through its
  // ends: a good calibration puts every corner on its line.
  const auto& corners = views.corners[std::size_t(best)];
  std::vector<cv::Point2f> straight;
  cv::undistortPoints(corners, straight, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients(),
                      cv::noArray(), cv::Mat(camera.camera_matrix()));
  const cv::Point3f first = views.objects[std::size_t(best)].front();
  int per_row = 0;
  for (const auto& q : views.objects[std::size_t(best)]) per_row += q.y == first.y ? 1 : 0;
  for (std::size_t s = 0; per_row > 1 && s + per_row <= straight.size(); s += std::size_t(per_row)) {
    cv::line(undistorted, straight[s], straight[s + std::size_t(per_row) - 1], cv::Scalar(0, 220, 0), 1, cv::LINE_AA);
    for (int k = 0; k < per_row; ++k)
      cv::circle(undistorted, straight[s + std::size_t(k)], 2, cv::Scalar(0, 0, 255), cv::FILLED, cv::LINE_AA);
  }
  text(original, "as recorded: " + it->name, {8, 20}, 0.5);
  text(undistorted, "undistorted: corners on their rows' straight lines", {8, 20}, 0.5);
  cv::Mat both;
  cv::hconcat(original, undistorted, both);
  write_image_atomically(path, both);
}

}  // namespace lumar::calib
