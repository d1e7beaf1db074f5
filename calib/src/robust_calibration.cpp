#include "lumar/calib/robust_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <random>

#include "lumar/base/error.h"
#include "lumar/base/stop_signal.h"

namespace lumar::calib {

namespace {

struct Solve {
  CameraIntrinsics intrinsics;
  double rms = 0;
  std::vector<double> per_view_rms;
  std::array<double, 9> std_dev{};
  std::vector<cv::Mat> rvecs;
};

int calibration_flags(const RobustCalibrationOptions& o) {
  return (o.fix_k3 ? cv::CALIB_FIX_K3 : 0) | (o.fix_aspect ? cv::CALIB_FIX_ASPECT_RATIO : 0);
}

double rms_of(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b) {
  double sum = 0;
  for (std::size_t j = 0; j < a.size(); ++j) {
    const cv::Point2f e = a[j] - b[j];
    sum += double(e.x) * e.x + double(e.y) * e.y;
  }
  return std::sqrt(sum / double(a.size()));
}

Solve solve(const BoardViews& views, const std::vector<int>& subset, const RobustCalibrationOptions& o) {
  std::vector<std::vector<cv::Point2f>> image_points;
  std::vector<std::vector<cv::Point3f>> object_points;
  for (int i : subset) {
    image_points.push_back(views.corners[i]);
    object_points.push_back(views.objects[i]);
  }
  // OpenCV's solve is dense: a minute over 150 views, which a stop must not wait for.
  struct Solved {
    double rms = 0;
    cv::Mat K, D, std_intrinsics;
    std::vector<cv::Mat> rvecs, tvecs;
  };
  const Solved solved = run_until_stopped(
      [object_points, image_points, size = views.image_size, flags = calibration_flags(o)] {
        Solved r;
        // With CALIB_FIX_ASPECT_RATIO OpenCV keeps the initial fx/fy ratio: start from 1.
        r.K = cv::Mat::eye(3, 3, CV_64F);
        cv::Mat std_extrinsics, per_view;
        r.rms = cv::calibrateCamera(object_points, image_points, size, r.K, r.D, r.rvecs, r.tvecs, r.std_intrinsics,
                                    std_extrinsics, per_view, flags);
        return r;
      },
      "calibrate: while solving for the intrinsics");
  const cv::Mat &K = solved.K, &D = solved.D, &std_intrinsics = solved.std_intrinsics;
  const std::vector<cv::Mat>& tvecs = solved.tvecs;
  Solve s;
  s.rms = solved.rms;
  s.rvecs = solved.rvecs;
  CameraIntrinsics& c = s.intrinsics;
  c.width = views.image_size.width;
  c.height = views.image_size.height;
  c.fx = K.at<double>(0, 0);
  c.fy = K.at<double>(1, 1);
  c.cx = K.at<double>(0, 2);
  c.cy = K.at<double>(1, 2);
  for (int i = 0; i < 5; ++i) c.distortion[i] = D.at<double>(i);
  for (int i = 0; i < 9; ++i) s.std_dev[i] = std_intrinsics.at<double>(i);
  for (std::size_t i = 0; i < image_points.size(); ++i) {
    std::vector<cv::Point2f> projected;
    cv::projectPoints(object_points[i], s.rvecs[i], tvecs[i], K, D, projected);
    s.per_view_rms.push_back(rms_of(projected, image_points[i]));
  }
  return s;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Held-out error of one split: intrinsics from `train`, then each test view's pose
// from its own corners (solvePnP) and the RMS of all test corners.
double holdout_rms(const BoardViews& views, const std::vector<int>& train, const std::vector<int>& test,
                   const RobustCalibrationOptions& o, double* training_rms) {
  const Solve s = solve(views, train, o);
  *training_rms = s.rms;
  const cv::Mat K(s.intrinsics.camera_matrix());
  const cv::Mat D = s.intrinsics.distortion_coefficients();
  double sum = 0;
  std::size_t count = 0;
  for (int i : test) {
    cv::Mat rvec, tvec;
    cv::solvePnP(views.objects[i], views.corners[i], K, D, rvec, tvec);
    std::vector<cv::Point2f> projected;
    cv::projectPoints(views.objects[i], rvec, tvec, K, D, projected);
    const double r = rms_of(projected, views.corners[i]);
    sum += r * r * double(projected.size());
    count += projected.size();
  }
  return std::sqrt(sum / double(count));
}

// Board normals (camera frame) more than `separation` apart from every earlier
// representative start a new orientation class.
int distinct_orientations(const std::vector<cv::Mat>& rvecs, double separation_deg) {
  std::vector<cv::Vec3d> classes;
  const double cos_sep = std::cos(separation_deg * CV_PI / 180.0);
  for (const cv::Mat& r : rvecs) {
    cv::Matx33d R;
    cv::Rodrigues(r, R);
    const cv::Vec3d normal(R(0, 2), R(1, 2), R(2, 2));
    const bool seen =
        std::any_of(classes.begin(), classes.end(), [&](const cv::Vec3d& n) { return n.dot(normal) > cos_sep; });
    if (!seen) classes.push_back(normal);
  }
  return int(classes.size());
}

}  // namespace

RobustCalibrationResult calibrate_robust(const BoardViews& views, const RobustCalibrationOptions& o) {
  const int n = int(views.corners.size());
  require_board_views(views, views.names.size() + views.views_without_board.size(), "board");
  RobustCalibrationResult result;
  result.views_without_board = views.views_without_board;

  std::vector<int> kept(n);
  std::iota(kept.begin(), kept.end(), 0);
  Solve s = solve(views, kept, o);
  result.initial_rms = s.rms;
  // One view at a time: a bad view bends the fit and inflates its neighbours' errors,
  // so only the worst is dropped before solving again.
  for (int round = 1; o.reject_outliers && int(kept.size()) > std::max(o.min_views, 3); ++round) {
    const double med = median(s.per_view_rms);
    std::vector<double> deviations;
    for (double r : s.per_view_rms) deviations.push_back(std::abs(r - med));
    const double mad = median(deviations);
    const double threshold = std::max(med + o.outlier_z * 1.4826 * mad, o.outlier_floor_px);
    const auto worst = std::max_element(s.per_view_rms.begin(), s.per_view_rms.end());
    if (*worst <= threshold) break;
    const std::size_t k = std::size_t(worst - s.per_view_rms.begin());
    throw_if_stopped("calibrate: while rejecting outlier views");
    result.rejected.push_back({views.names[kept[k]], *worst, threshold, round});
    kept.erase(kept.begin() + std::ptrdiff_t(k));
    s = solve(views, kept, o);
  }

  result.camera.intrinsics = s.intrinsics;
  result.camera.avg_reprojection_error = s.rms;
  result.per_view_rms = s.per_view_rms;
  result.std_dev = s.std_dev;
  for (int i : kept) result.used_views.push_back(views.names[i]);

  // Cross-validation over random halves of the kept views.
  const int m = int(kept.size());
  if (m >= 6) {
    std::mt19937 rng(o.seed);
    double holdout = 0, training = 0;
    for (int split = 0; split < o.holdout_splits; ++split) {
      throw_if_stopped("calibrate: while cross-validating");
      std::vector<int> order = kept;
      std::shuffle(order.begin(), order.end(), rng);
      const std::vector<int> train(order.begin(), order.begin() + m / 2);
      const std::vector<int> test(order.begin() + m / 2, order.end());
      double t = 0;
      holdout += holdout_rms(views, train, test, o, &t);
      training += t;
    }
    result.holdout_splits = o.holdout_splits;
    if (o.holdout_splits > 0) {
      result.holdout_rms = holdout / o.holdout_splits;
      result.training_rms = training / o.holdout_splits;
    }
  } else {
    result.warnings.push_back("only " + std::to_string(m) +
                              " views kept: too few to cross-validate; add views at varied angles");
  }

  // Coverage of the sensor by the kept views' corners.
  std::vector<char> occupied(std::size_t(o.coverage_cols * o.coverage_rows), 0);
  for (int i : kept)
    for (const cv::Point2f& p : views.corners[i]) {
      const int cx = std::clamp(int(p.x * o.coverage_cols / views.image_size.width), 0, o.coverage_cols - 1);
      const int cy = std::clamp(int(p.y * o.coverage_rows / views.image_size.height), 0, o.coverage_rows - 1);
      occupied[std::size_t(cy * o.coverage_cols + cx)] = 1;
    }
  result.coverage = double(std::count(occupied.begin(), occupied.end(), 1)) / double(occupied.size());
  result.orientations = distinct_orientations(s.rvecs, o.orientation_separation_deg);
  char line[256];
  if (result.coverage < o.min_coverage) {
    std::snprintf(line, sizeof line,
                  "corners cover only %.0f%% of the %dx%d sensor grid (want %.0f%%); add views with the board "
                  "near the edges and corners",
                  100 * result.coverage, o.coverage_cols, o.coverage_rows, 100 * o.min_coverage);
    result.warnings.emplace_back(line);
  }
  if (result.orientations < o.min_orientations) {
    std::snprintf(line, sizeof line,
                  "only %d distinct board orientation(s) (want %d, %.0f deg apart); tilt the board differently",
                  result.orientations, o.min_orientations, o.orientation_separation_deg);
    result.warnings.emplace_back(line);
  }
  // A distortion term within two standard deviations of zero is not measured by these
  // views: the fit spent a degree of freedom on noise (and k2 and k3 trade off against
  // each other, so each can look large while neither is known).
  const auto& d = result.camera.intrinsics.distortion;
  const struct {
    const char* name;
    double value, sigma;
    const char* hint;
  } terms[] = {{"k2", d[1], result.std_dev[5], "more views near the image corners pin it down"},
               {"k3", d[4], result.std_dev[8], "fix it with --fix-k3 unless the lens is wide-angle"}};
  for (const auto& t : terms)
    if (t.sigma > 0 && std::abs(t.value) < 2 * t.sigma) {
      std::snprintf(line, sizeof line, "%s = %.4f ± %.4f is not significant (|%s| < 2 sigma); %s", t.name, t.value,
                    t.sigma, t.name, t.hint);
      result.warnings.emplace_back(line);
    }
  return result;
}

}  // namespace lumar::calib
