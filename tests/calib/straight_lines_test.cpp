// Acceptance (issue 5, Undistortion): straight lines of a synthetic distorted image come
// out straight. Families of straight lines are drawn in a finely sampled pinhole image,
// distorted with the real webcam calibration (strong barrel), undistorted with the maps,
// and each line's straightness is measured from sub-pixel centroids of its profile. The
// same measurement on the distorted image shows the bending it removes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "lumar/calib/camera_file.h"
#include "lumar/calib/undistortion.h"
#include "test_paths.h"

namespace lumar::calib {
namespace {

// A family of parallel lines in normalized image coordinates (x/z, y/z):
// x cos(angle) + y sin(angle) = k * spacing.
struct LineFamily {
  double angle_deg;  // direction of the lines' normal from the x axis
  bool transposed;   // measure along columns (for near-horizontal lines)
};

constexpr double kSpacing = 0.1;      // normalized units: ~54 px at the webcam's focal length
constexpr double kSigmaPixels = 1.5;  // line profile at the webcam's focal length

// Anti-aliased by construction: each pixel is the Gaussian of its distance to the
// nearest line, so no pixel grid leaks into the line's position.
cv::Mat draw_lines(const CameraIntrinsics& pinhole, const LineFamily& family, double reference_fx) {
  const double a = family.angle_deg * CV_PI / 180.0, ca = std::cos(a), sa = std::sin(a);
  const double sigma = kSigmaPixels / reference_fx;
  cv::Mat image(pinhole.height, pinhole.width, CV_32F);
  for (int r = 0; r < image.rows; ++r) {
    float* row = image.ptr<float>(r);
    const double y = (r - pinhole.cy) / pinhole.fy;
    for (int c = 0; c < image.cols; ++c) {
      const double x = (c - pinhole.cx) / pinhole.fx;
      const double t = x * ca + y * sa;
      const double d = t - std::round(t / kSpacing) * kSpacing;
      row[c] = float(std::exp(-d * d / (2 * sigma * sigma)));
    }
  }
  return image;
}

struct Straightness {
  int lines = 0;
  double worst_rms = 0;  // px: worst line's RMS perpendicular distance from its fitted line
  double mean_rms = 0;
};

// RMS perpendicular distance of points from their total-least-squares line.
double line_fit_rms(const std::vector<cv::Point2d>& points) {
  cv::Point2d mean(0, 0);
  for (const auto& p : points) mean += p;
  mean *= 1.0 / points.size();
  double sxx = 0, syy = 0, sxy = 0;
  for (const auto& p : points) {
    const cv::Point2d d = p - mean;
    sxx += d.x * d.x, syy += d.y * d.y, sxy += d.x * d.y;
  }
  sxx /= points.size(), syy /= points.size(), sxy /= points.size();
  // Smallest eigenvalue of the covariance = mean squared perpendicular residual.
  const double smallest = 0.5 * (sxx + syy) - std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
  return std::sqrt(std::max(smallest, 0.0));
}

// Lines must run roughly along the columns of `image` (rows cut across them). `valid`
// marks pixels that saw the scene; a profile touching anything else is skipped.
Straightness measure_lines(const cv::Mat& image, const cv::Mat& valid) {
  cv::Mat mask = (image > 0.2) & valid, labels;
  const int count = cv::connectedComponents(mask, labels, 8, CV_32S);
  std::map<int, std::vector<cv::Point2d>> centroids;
  constexpr int kMargin = 4;  // profile tails: exp(-(4 + half width)^2 / 2 sigma^2) is negligible
  for (int r = 0; r < image.rows; ++r) {
    const int* lab = labels.ptr<int>(r);
    std::map<int, std::pair<int, int>> runs;  // label -> first, last column
    std::map<int, int> pieces;
    for (int c = 0; c < image.cols; ++c) {
      if (lab[c] == 0) continue;
      auto [it, fresh] = runs.try_emplace(lab[c], c, c);
      if (!fresh && it->second.second != c - 1) ++pieces[lab[c]];  // the line crosses this row twice
      it->second.second = c;
    }
    for (const auto& [label, run] : runs) {
      if (pieces[label] > 0) continue;
      const int c0 = run.first - kMargin, c1 = run.second + kMargin;
      if (c0 < 0 || c1 >= image.cols) continue;
      bool clean = true;
      double sum = 0, moment = 0;
      for (int c = c0; c <= c1 && clean; ++c) {
        clean = valid.at<uchar>(r, c) != 0 && (lab[c] == 0 || lab[c] == label);
        sum += image.at<float>(r, c);
        moment += image.at<float>(r, c) * c;
      }
      if (clean) centroids[label].push_back({moment / sum, double(r)});
    }
  }
  Straightness s;
  for (int label = 1; label < count; ++label) {
    const auto& points = centroids[label];
    if (points.size() < 60) continue;  // too short a piece to say anything about straightness
    const double rms = line_fit_rms(points);
    s.worst_rms = std::max(s.worst_rms, rms);
    s.mean_rms += rms;
    ++s.lines;
  }
  if (s.lines > 0) s.mean_rms /= s.lines;
  return s;
}

Straightness measure(const cv::Mat& image, const cv::Mat& valid, bool transposed) {
  if (!transposed) return measure_lines(image, valid);
  return measure_lines(image.t(), cv::Mat(valid.t()));
}

const char* mode_name(UndistortedCamera mode) {
  switch (mode) {
    case UndistortedCamera::SameMatrix:
      return "SameMatrix";
    case UndistortedCamera::CropToValid:
      return "CropToValid";
    case UndistortedCamera::KeepAll:
      return "KeepAll";
  }
  return "?";
}

TEST(StraightLines, UndistortedImageOfStraightLinesHasStraightLines) {
  const CameraIntrinsics camera = load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  ASSERT_TRUE(camera.has_distortion());

  // Pinhole image of the scene: twice the webcam's resolution at its centre, wide enough
  // (normalized |x| <= 1, |y| <= 0.85) to hold everything the distorted corners see.
  CameraIntrinsics pinhole = camera.without_distortion();
  pinhole.fx = pinhole.fy = 2.0 * camera.fx;
  pinhole.width = 2 * int(std::ceil(1.0 * pinhole.fx));
  pinhole.height = 2 * int(std::ceil(0.85 * pinhole.fy));
  pinhole.cx = 0.5 * (pinhole.width - 1);
  pinhole.cy = 0.5 * (pinhole.height - 1);

  // Which distorted pixels saw the scene (all of them, given the margins above).
  const cv::Mat ones(pinhole.height, pinhole.width, CV_32F, cv::Scalar(1));
  const cv::Mat distorted_coverage = distort_image(ones, pinhole, camera);
  const cv::Mat distorted_valid = distorted_coverage > 0.999f;
  ASSERT_EQ(cv::countNonZero(distorted_valid), camera.width * camera.height);

  // Vertical, horizontal and tilted lines (tilted 25 degrees off vertical).
  const std::vector<LineFamily> families = {{0, false}, {90, true}, {25, false}};
  std::vector<cv::Mat> distorted;
  Straightness bent;  // worst over the families, distorted image
  int bent_lines = 0;
  for (const auto& family : families) {
    distorted.push_back(distort_image(draw_lines(pinhole, family, camera.fx), pinhole, camera));
    const Straightness s = measure(distorted.back(), distorted_valid, family.transposed);
    bent.worst_rms = std::max(bent.worst_rms, s.worst_rms);
    bent_lines += s.lines;
  }
  std::printf("distorted image: %d lines, worst RMS residual %.3f px\n", bent_lines, bent.worst_rms);
  // The measurement sees the lens: without undistortion the lines are visibly bent.
  EXPECT_GT(bent_lines, 20);
  EXPECT_GT(bent.worst_rms, 1.0);

  for (const auto mode : {UndistortedCamera::SameMatrix, UndistortedCamera::CropToValid, UndistortedCamera::KeepAll}) {
    SCOPED_TRACE(mode_name(mode));
    const UndistortionMaps maps = make_undistortion_maps(camera, mode);
    const cv::Mat valid = undistort_image(distorted_coverage, maps) > 0.999f;
    int lines = 0;
    double worst = 0, mean = 0;
    for (std::size_t i = 0; i < families.size(); ++i) {
      const Straightness s = measure(undistort_image(distorted[i], maps), valid, families[i].transposed);
      EXPECT_GE(s.lines, 5) << "family " << families[i].angle_deg;
      worst = std::max(worst, s.worst_rms);
      mean += s.mean_rms * s.lines;
      lines += s.lines;
    }
    std::printf("%s: %d lines, worst RMS residual %.4f px, mean %.4f px\n", mode_name(mode), lines, worst,
                mean / std::max(lines, 1));
    EXPECT_LT(worst, 0.1);
  }

  // The 0.1 px bound is tight enough to catch a lens model 5 % off in k1.
  CameraIntrinsics wrong = camera;
  wrong.distortion[0] *= 0.95;
  const UndistortionMaps wrong_maps = make_undistortion_maps(wrong, UndistortedCamera::SameMatrix);
  const cv::Mat wrong_valid = undistort_image(distorted_coverage, wrong_maps) > 0.999f;
  double wrong_worst = 0;
  for (std::size_t i = 0; i < families.size(); ++i)
    wrong_worst = std::max(
        wrong_worst, measure(undistort_image(distorted[i], wrong_maps), wrong_valid, families[i].transposed).worst_rms);
  std::printf("SameMatrix with k1 5%% off: worst RMS residual %.3f px\n", wrong_worst);
  EXPECT_GT(wrong_worst, 0.1);
}

}  // namespace
}  // namespace lumar::calib
