#include "lumar/calib/vignetting.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "lumar/base/error.h"

namespace lumar::calib {
namespace {

double half_diagonal(cv::Size size) { return 0.5 * std::hypot(double(size.width), double(size.height)); }

cv::Mat to_grey(const cv::Mat& image, const char* what) {
  if (image.empty() || image.depth() != CV_32F || (image.channels() != 1 && image.channels() != 3))
    throw InputError(std::string(what) +
                     ": image is empty or not a linear float image with 1 or 3 channels; "
                     "linearize the video first");
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::transform(image, grey, cv::Matx13f(1.f / 3, 1.f / 3, 1.f / 3));
  return grey;
}

}  // namespace

cv::Mat vignetting_gain(cv::Size size, double a, double b, double cx, double cy) {
  const double inv = 1.0 / half_diagonal(size);
  cv::Mat gain(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y) {
    float* g = gain.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      const double dx = (x - cx) * inv, dy = (y - cy) * inv;
      const double r2 = dx * dx + dy * dy;
      g[x] = float(1.0 + a * r2 + b * r2 * r2);
    }
  }
  return gain;
}

VignettingFit estimate_vignetting(const cv::Mat& linear_flat_field, double cx, double cy) {
  const cv::Mat grey = to_grey(linear_flat_field, "vignetting flat field");
  const cv::Size size = grey.size();
  if (!(cx >= 0 && cx <= size.width - 1 && cy >= 0 && cy <= size.height - 1))
    throw InputError("vignetting flat field: principal point (" + std::to_string(cx) + ", " + std::to_string(cy) +
                     ") lies outside the image; check the camera calibration");
  // Block means average the noise down; the model is linear in (1, r^2, r^4), so
  // averaging those features over the same block keeps the fit exact.
  const int block = std::max(1, std::min(size.width, size.height) / 48);
  const double inv = 1.0 / half_diagonal(size);
  struct Sample {
    double value, r2, r4;
  };
  std::vector<Sample> samples;
  for (int by = 0; by + block <= size.height; by += block) {
    for (int bx = 0; bx + block <= size.width; bx += block) {
      double v = 0, r2 = 0, r4 = 0;
      for (int y = by; y < by + block; ++y) {
        const float* p = grey.ptr<float>(y);
        for (int x = bx; x < bx + block; ++x) {
          const double dx = (x - cx) * inv, dy = (y - cy) * inv, q = dx * dx + dy * dy;
          v += p[x];
          r2 += q;
          r4 += q * q;
        }
      }
      const double n = double(block) * block;
      if (std::isfinite(v)) samples.push_back({v / n, r2 / n, r4 / n});
    }
  }
  if (samples.size() < 3)
    throw InputError("vignetting flat field: image too small to fit a fall-off; give a full-resolution frame");

  std::vector<bool> inlier(samples.size(), true);
  cv::Vec3d coef;  // level, level * a, level * b
  double rms = 0.0;
  int inliers = 0;
  for (int iteration = 0; iteration < 5; ++iteration) {
    cv::Matx33d ata = cv::Matx33d::zeros();
    cv::Vec3d atb(0, 0, 0);
    for (size_t i = 0; i < samples.size(); ++i) {
      if (!inlier[i]) continue;
      const cv::Vec3d row(1.0, samples[i].r2, samples[i].r4);
      ata += row * row.t();
      atb += samples[i].value * row;
    }
    cv::Mat solution;
    const bool solved = cv::solve(cv::Mat(ata), cv::Mat(atb), solution, cv::DECOMP_CHOLESKY);
    if (solved) coef = cv::Vec3d(solution.ptr<double>());
    if (!solved || !(coef[0] > 0))
      throw InputError("vignetting flat field: cannot fit a fall-off (is the image flat, lit and unsaturated?)");
    std::vector<double> residuals(samples.size());
    std::vector<double> abs_inlier;
    for (size_t i = 0; i < samples.size(); ++i) {
      residuals[i] = samples[i].value - (coef[0] + coef[1] * samples[i].r2 + coef[2] * samples[i].r4);
      if (inlier[i]) abs_inlier.push_back(std::abs(residuals[i]));
    }
    // Median absolute deviation: a scale that the outliers themselves cannot inflate.
    std::nth_element(abs_inlier.begin(), abs_inlier.begin() + long(abs_inlier.size() / 2), abs_inlier.end());
    const double sigma = std::max(1.4826 * abs_inlier[abs_inlier.size() / 2], 1e-12 * coef[0]);
    double sum2 = 0.0;
    inliers = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
      inlier[i] = std::abs(residuals[i]) <= 3.0 * sigma;
      if (inlier[i]) {
        sum2 += residuals[i] * residuals[i];
        ++inliers;
      }
    }
    rms = std::sqrt(sum2 / std::max(inliers, 1));
    if (inliers < 3)
      throw InputError("vignetting flat field: too few consistent samples; give an evenly lit flat field");
  }
  VignettingFit fit;
  fit.level = coef[0];
  fit.a = coef[1] / coef[0];
  fit.b = coef[2] / coef[0];
  fit.residual_rms = rms / coef[0];
  fit.inliers = inliers;
  fit.samples = int(samples.size());
  return fit;
}

cv::Mat correct_vignetting(const cv::Mat& linear_image, double a, double b, double cx, double cy) {
  if (linear_image.empty() || linear_image.depth() != CV_32F ||
      (linear_image.channels() != 1 && linear_image.channels() != 3))
    throw InputError(
        "correct vignetting: image is empty or not a linear float image with 1 or 3 channels; "
        "linearize the video first");
  cv::Mat gain = vignetting_gain(linear_image.size(), a, b, cx, cy);
  if (linear_image.channels() == 3) cv::merge(std::vector<cv::Mat>{gain, gain, gain}, gain);
  cv::Mat out;
  cv::divide(linear_image, gain, out);
  return out;
}

}  // namespace lumar::calib
