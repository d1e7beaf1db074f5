#include "lumar/envmap/envmap_stitcher.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/base/latlong.h"

namespace lumar::calib {

namespace {

// The largest squared normalised radius (x/z, y/z) of any ray through the image,
// sampled along the border of the pixel area (distortion is radial-dominant, so the
// border holds the extremes).
double max_ray_radius2(const CameraIntrinsics& camera) {
  std::vector<cv::Point2d> border;
  const double x0 = -0.5, y0 = -0.5, x1 = camera.width - 0.5, y1 = camera.height - 0.5;
  for (int k = 0; k <= 64; ++k) {
    const double s = k / 64.0;
    border.emplace_back(x0 + s * (x1 - x0), y0);
    border.emplace_back(x0 + s * (x1 - x0), y1);
    border.emplace_back(x0, y0 + s * (y1 - y0));
    border.emplace_back(x1, y0 + s * (y1 - y0));
  }
  std::vector<cv::Point2d> normalized;
  cv::undistortPoints(border, normalized, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients(),
                      cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 60, 1e-12));
  double r2 = 0;
  for (const auto& p : normalized) r2 = std::max(r2, p.x * p.x + p.y * p.y);
  return r2;
}

}  // namespace

EnvmapStitcher::EnvmapStitcher(const StitchSettings& settings) : settings_(settings) {
  if (settings.width <= 0 || settings.width % 2 != 0)
    throw InputError("envmap: map width " + std::to_string(settings.width) + " must be a positive even number");
  if (!settings.camera.is_valid()) throw InputError("envmap: the camera calibration is not valid");
  width_ = settings.width;
  height_ = settings.width / 2;
  const std::size_t n = std::size_t(width_) * height_;
  directions_.resize(n * 3);
  row_theta_.resize(height_);
  for (int r = 0; r < height_; ++r) {
    row_theta_[r] = float(kPi * (r + 0.5) / height_);
    for (int c = 0; c < width_; ++c) {
      const glm::dvec3 d = latlong_pixel_direction(c, r, width_, height_);
      float* o = &directions_[(std::size_t(r) * width_ + c) * 3];
      o[0] = float(d.x), o[1] = float(d.y), o[2] = float(d.z);
    }
  }
  accum_.assign(n * 4, 0.f);
  count_.assign(n, 0);
  peak_code_.assign(n, 0.f);
  fallback_.assign(n * 3, 0.f);
  fallback_kind_.assign(n, 0);
  for (int ch = 0; ch < 3; ++ch)
    for (int v = 0; v < 256; ++v) lut_[ch][v] = settings.response(ch, v);
  // A little beyond the border so that the outermost pixels still find their rays.
  max_ray_r2_ = max_ray_radius2(settings.camera) * 1.02;
  cone_half_angle_ = std::atan(std::sqrt(max_ray_r2_));
  // Pre-filter: sample the camera image at the level whose pixel is no finer than the
  // map's (a map pixel spans 2 pi / W radians, a camera pixel about 1 / fx), so a coarse
  // map averages what it covers instead of point-sampling it.
  if (settings.prefilter) {
    const double ratio = 2.0 * kPi * std::max(settings.camera.fx, settings.camera.fy) / width_;
    level_ = std::clamp(int(std::floor(std::log2(std::max(ratio, 1.0)))), 0, 5);
  }
}

void EnvmapStitcher::prepare_levels(const cv::Mat& image, double exposure) {
  const CameraIntrinsics& cam = settings_.camera;
  if (levels_.empty()) levels_.resize(std::size_t(level_) + 1);
  Level& l0 = levels_[0];
  l0.width = cam.width, l0.height = cam.height;
  const std::size_t n = std::size_t(cam.width) * cam.height;
  l0.rgb.resize(n * 3), l0.weight.resize(n), l0.code.resize(n), l0.clipped.resize(n);
  const double inv_hd2 = 4.0 / (double(cam.width) * cam.width + double(cam.height) * cam.height);
  const float va = float(settings_.vignetting_a), vb = float(settings_.vignetting_b);
  const int sat = settings_.saturated_value, dark = settings_.dark_value;
  // Linear radiance (response, vignetting, exposure undone) and how far to trust it.
  tbb::parallel_for(0, cam.height, [&](int y) {
    const uchar* p = image.ptr<uchar>(y);
    for (int x = 0; x < cam.width; ++x, p += 3) {
      const std::size_t i = std::size_t(y) * cam.width + x;
      const float rr = float(((x - cam.cx) * (x - cam.cx) + (y - cam.cy) * (y - cam.cy)) * inv_hd2);
      const float scale = float(1.0 / exposure) / (1.f + rr * (va + vb * rr));
      l0.rgb[i * 3] = lut_[2][p[2]] * scale, l0.rgb[i * 3 + 1] = lut_[1][p[1]] * scale,
                 l0.rgb[i * 3 + 2] = lut_[0][p[0]] * scale;
      const int vmax = std::max({p[0], p[1], p[2]});
      l0.clipped[i] = vmax >= sat;
      l0.code[i] = float(vmax);
      // Ramps up from the dark level (8-bit steps are coarse there), down towards clipping.
      l0.weight[i] = (vmax >= sat || vmax <= dark)
                         ? 0.f
                         : std::min(1.f, float(vmax - dark) / 48.f) * std::min(1.f, float(sat - vmax) / 16.f);
    }
  });
  // Box pyramid: radiance and trust averaged, clipping kept if any pixel below clipped.
  for (std::size_t k = 1; k < levels_.size(); ++k) {
    const Level& f = levels_[k - 1];
    Level& c = levels_[k];
    c.width = std::max(1, f.width / 2), c.height = std::max(1, f.height / 2);
    const std::size_t m = std::size_t(c.width) * c.height;
    c.rgb.resize(m * 3), c.weight.resize(m), c.code.resize(m), c.clipped.resize(m);
    tbb::parallel_for(0, c.height, [&](int y) {
      for (int x = 0; x < c.width; ++x) {
        const std::size_t o = std::size_t(y) * c.width + x;
        float sum[3] = {0, 0, 0}, w = 0, code = 0;
        std::uint8_t clip = 0;
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const std::size_t i =
                std::size_t(std::min(2 * y + dy, f.height - 1)) * f.width + std::min(2 * x + dx, f.width - 1);
            sum[0] += f.rgb[i * 3], sum[1] += f.rgb[i * 3 + 1], sum[2] += f.rgb[i * 3 + 2];
            w += f.weight[i];
            code += f.code[i];
            clip |= f.clipped[i];
          }
        c.rgb[o * 3] = 0.25f * sum[0], c.rgb[o * 3 + 1] = 0.25f * sum[1], c.rgb[o * 3 + 2] = 0.25f * sum[2];
        c.weight[o] = 0.25f * w;
        c.code[o] = 0.25f * code;
        c.clipped[o] = clip;
      }
    });
  }
}

void EnvmapStitcher::add_frame(const cv::Mat& image, const glm::dquat& R_world_camera, double exposure) {
  const CameraIntrinsics& cam = settings_.camera;
  if (image.type() != CV_8UC3 || image.cols != cam.width || image.rows != cam.height)
    throw InputError("envmap: frame is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                     " but the calibration is for " + std::to_string(cam.width) + "x" + std::to_string(cam.height) +
                     " BGR8; use the calibration of this camera");
  if (!(exposure > 0) || !std::isfinite(exposure)) throw InputError("envmap: frame exposure must be positive");

  // Map direction -> camera: d_cam = R_camera_world * Ry(offset) * d_map.
  const double a = glm::radians(settings_.azimuth_offset_deg);
  const glm::dmat3 Ry_cols(glm::dvec3(std::cos(a), 0, -std::sin(a)), glm::dvec3(0, 1, 0),
                           glm::dvec3(std::sin(a), 0, std::cos(a)));
  const glm::dmat3 R_dm = glm::transpose(glm::mat3_cast(R_world_camera)) * Ry_cols;
  const glm::mat3 R(R_dm);
  // Optical axis in the map frame: the third row of R.
  const glm::dvec3 axis(R_dm[0][2], R_dm[1][2], R_dm[2][2]);
  const double theta_f = std::acos(std::clamp(axis.y, -1.0, 1.0));
  const double phi_f = std::atan2(axis.z, axis.x);
  const double margin = 1.5 * kPi / height_;
  const double alpha = std::min(cone_half_angle_ + margin, kPi);
  const double cos_alpha = std::cos(alpha);
  const int row0 = std::max(0, int(std::floor((theta_f - alpha) / kPi * height_)) - 1);
  const int row1 = std::min(height_ - 1, int(std::ceil((theta_f + alpha) / kPi * height_)) + 1);

  const float fx = float(cam.fx), fy = float(cam.fy), cx = float(cam.cx), cy = float(cam.cy);
  const float k1 = float(cam.distortion[0]), k2 = float(cam.distortion[1]), p1 = float(cam.distortion[2]),
              p2 = float(cam.distortion[3]), k3 = float(cam.distortion[4]);
  const float max_r2 = float(max_ray_r2_);
  const float umax = float(cam.width - 1), vmax_px = float(cam.height - 1);
  const float inv_hd2 = float(4.0 / (double(cam.width) * cam.width + double(cam.height) * cam.height));
  const float edge = float(settings_.edge_weight);
  // A radiance estimate's noise scales with 1 / exposure, so its weight goes with
  // exposure^2 (relative to the first frame's, to keep the sums near 1): where a longer
  // exposure saw a pixel unclipped, the shorter ones barely count.
  if (frames_ == 0) reference_exposure_ = exposure;
  const float exposure_weight = float(std::pow(exposure / reference_exposure_, 2));
  prepare_levels(image, exposure);
  const Level& level = levels_[std::min<std::size_t>(levels_.size() - 1, std::size_t(level_))];
  const int lw = level.width, lh = level.height;
  const float level_scale = 1.f / float(1 << std::min<std::size_t>(levels_.size() - 1, std::size_t(level_)));
  const double sin_f = std::sin(theta_f), cos_f = std::cos(theta_f);
  const double column_margin = 2.0 * 2.0 * kPi / width_;

  tbb::parallel_for(row0, row1 + 1, [&](int r) {
    const double theta = row_theta_[r];
    const double denom = std::sin(theta) * sin_f;
    int c_begin = 0, c_count = width_;
    if (denom > 1e-9) {
      const double c = (cos_alpha - std::cos(theta) * cos_f) / denom;
      if (c > 1.0) return;  // the cone misses this row
      if (c > -1.0) {
        const double half = std::acos(c) + column_margin;
        if (half < kPi) {
          c_begin = int(std::floor((phi_f - half) / (2 * kPi) * width_ - 0.5));
          c_count = std::min(width_, int(std::ceil(2 * half / (2 * kPi) * width_)) + 2);
        }
      }
    }
    for (int k = 0; k < c_count; ++k) {
      const int col = ((c_begin + k) % width_ + width_) % width_;
      const std::size_t idx = std::size_t(r) * width_ + col;
      const float* d = &directions_[idx * 3];
      const glm::vec3 p = R * glm::vec3(d[0], d[1], d[2]);
      if (p.z <= 0.f) continue;
      const float x = p.x / p.z, y = p.y / p.z;
      const float r2 = x * x + y * y;
      if (r2 > max_r2) continue;
      const float radial = 1.f + r2 * (k1 + r2 * (k2 + r2 * k3));
      const float xd = x * radial + 2.f * p1 * x * y + p2 * (r2 + 2.f * x * x);
      const float yd = y * radial + p1 * (r2 + 2.f * y * y) + 2.f * p2 * x * y;
      const float u = fx * xd + cx, v = fy * yd + cy;
      if (!(u >= 0.f && u <= umax && v >= 0.f && v <= vmax_px)) continue;
      // Sample the pre-filtered level whose pixels match the map's.
      const float ul = std::clamp((u + 0.5f) * level_scale - 0.5f, 0.f, float(lw - 1));
      const float vl = std::clamp((v + 0.5f) * level_scale - 0.5f, 0.f, float(lh - 1));
      const int u0 = std::min(int(ul), std::max(0, lw - 2)), v0 = std::min(int(vl), std::max(0, lh - 2));
      const int u1 = std::min(u0 + 1, lw - 1), v1 = std::min(v0 + 1, lh - 1);
      const float fu = ul - u0, fv = vl - v0;
      const std::size_t taps[4] = {std::size_t(v0) * lw + u0, std::size_t(v0) * lw + u1, std::size_t(v1) * lw + u0,
                                   std::size_t(v1) * lw + u1};
      const float tw[4] = {(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv};
      float rgb[3] = {0, 0, 0}, w_value = 0, code = 0;
      bool clipped = false;
      for (int t = 0; t < 4; ++t) {
        const float* c = &level.rgb[taps[t] * 3];
        rgb[0] += tw[t] * c[0], rgb[1] += tw[t] * c[1], rgb[2] += tw[t] * c[2];
        w_value += tw[t] * level.weight[taps[t]];
        code += tw[t] * level.code[taps[t]];
        clipped |= level.clipped[taps[t]] != 0;
      }
      if (!clipped) peak_code_[idx] = std::max(peak_code_[idx], code);
      const float du = u - cx, dv = v - cy;
      const float rr = (du * du + dv * dv) * inv_hd2;
      if (count_[idx] < 65535) ++count_[idx];
      if (clipped || w_value <= 1e-6f) {
        const std::uint8_t kind = clipped ? 2 : 1;
        float* f = &fallback_[idx * 3];
        const float lum = rgb[0] + rgb[1] + rgb[2], old = f[0] + f[1] + f[2];
        const bool take =
            kind > fallback_kind_[idx] || (kind == fallback_kind_[idx] && (clipped ? lum > old : lum < old));
        if (take) {
          f[0] = rgb[0], f[1] = rgb[1], f[2] = rgb[2];
          fallback_kind_[idx] = kind;
        }
        continue;
      }
      const float w = w_value * exposure_weight * (1.f - (1.f - edge) * std::min(1.f, rr));
      float* acc = &accum_[idx * 4];
      acc[0] += w * rgb[0], acc[1] += w * rgb[1], acc[2] += w * rgb[2], acc[3] += w;
    }
  });
  ++frames_;
}

EnvironmentMap EnvmapStitcher::current_map() const {
  EnvironmentMap map;
  map.width = width_;
  map.height = height_;
  map.capture_position = settings_.capture_position;
  map.azimuth_offset_deg = settings_.azimuth_offset_deg;
  const std::size_t n = std::size_t(width_) * height_;
  map.rgb.assign(n * 3, 0.f);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
    const float* acc = &accum_[i * 4];
    float* o = &map.rgb[i * 3];
    if (acc[3] > 0.f) {
      for (int c = 0; c < 3; ++c) o[c] = acc[c] / acc[3];
    } else if (fallback_kind_[i] != 0) {
      for (int c = 0; c < 3; ++c) o[c] = fallback_[i * 3 + c];
    }
  });
  return map;
}

cv::Mat EnvmapStitcher::weights() const {
  cv::Mat w(height_, width_, CV_32FC1);
  for (int r = 0; r < height_; ++r)
    for (int c = 0; c < width_; ++c) w.at<float>(r, c) = accum_[(std::size_t(r) * width_ + c) * 4 + 3];
  return w;
}

cv::Mat EnvmapStitcher::coverage() const {
  cv::Mat m(height_, width_, CV_16UC1);
  std::copy(count_.begin(), count_.end(), m.ptr<std::uint16_t>(0));
  return m;
}

cv::Mat EnvmapStitcher::clipped() const {
  cv::Mat m(height_, width_, CV_8UC1);
  for (std::size_t i = 0; i < count_.size(); ++i)
    m.data[i] = (accum_[i * 4 + 3] <= 0.f && fallback_kind_[i] == 2) ? 255 : 0;
  return m;
}

cv::Mat EnvmapStitcher::near_black() const {
  cv::Mat m(height_, width_, CV_8UC1);
  for (std::size_t i = 0; i < count_.size(); ++i)
    m.data[i] = (accum_[i * 4 + 3] > 0.f && peak_code_[i] < kNearBlackCode) ? 255 : 0;
  return m;
}

}  // namespace lumar::calib
