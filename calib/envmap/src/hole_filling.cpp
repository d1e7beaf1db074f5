#include "lumar/envmap/hole_filling.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "lumar/base/color.h"
#include "lumar/base/error.h"

namespace lumar::calib {

namespace {

// Premultiplied colour (3 channels) and weight in [0, 1], CV_32FC4.
cv::Mat pull(const cv::Mat& fine) {
  const int w = std::max(1, fine.cols / 2), h = std::max(1, fine.rows / 2);
  cv::Mat coarse(h, w, CV_32FC4);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      cv::Vec4f sum(0, 0, 0, 0);
      for (int dr = 0; dr < 2; ++dr)
        for (int dc = 0; dc < 2; ++dc) {
          const int rr = std::min(fine.rows - 1, 2 * r + dr), cc = std::min(fine.cols - 1, 2 * c + dc);
          sum += fine.at<cv::Vec4f>(rr, cc);
        }
      // Saturate the weight at 1 but keep the colour an average of what is known.
      const float wsum = sum[3];
      if (wsum > 0.f) {
        const float s = std::min(1.f, wsum) / wsum;
        sum *= s;
      }
      coarse.at<cv::Vec4f>(r, c) = sum;
    }
  return coarse;
}

// Bilinear up-sampling that wraps in azimuth (columns) and clamps at the poles.
cv::Mat upsample(const cv::Mat& coarse, cv::Size size) {
  cv::Mat padded;
  cv::copyMakeBorder(coarse, padded, 0, 0, 1, 1, cv::BORDER_WRAP);
  cv::Mat out(size, CV_32FC4);
  const double sx = double(coarse.cols) / size.width, sy = double(coarse.rows) / size.height;
  for (int r = 0; r < size.height; ++r) {
    const double y = std::clamp((r + 0.5) * sy - 0.5, 0.0, double(coarse.rows - 1));
    const int y0 = std::min(int(y), coarse.rows - 1), y1 = std::min(y0 + 1, coarse.rows - 1);
    const float fy = float(y - y0);
    for (int c = 0; c < size.width; ++c) {
      const double x = (c + 0.5) * sx - 0.5 + 1.0;  // +1: the wrapped pad column
      const int x0 = int(std::floor(x)), x1 = x0 + 1;
      const float fx = float(x - x0);
      const cv::Vec4f a = padded.at<cv::Vec4f>(y0, x0) * (1 - fx) + padded.at<cv::Vec4f>(y0, x1) * fx;
      const cv::Vec4f b = padded.at<cv::Vec4f>(y1, x0) * (1 - fx) + padded.at<cv::Vec4f>(y1, x1) * fx;
      out.at<cv::Vec4f>(r, c) = a * (1 - fy) + b * fy;
    }
  }
  return out;
}

}  // namespace

int fill_holes_push_pull(EnvironmentMap& map, const cv::Mat& known) {
  if (known.rows != map.height || known.cols != map.width)
    throw InputError("envmap: the known-pixel mask does not match the map size");
  cv::Mat mask;
  known.convertTo(mask, CV_32F);
  cv::Mat level0(map.height, map.width, CV_32FC4);
  int holes = 0;
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < map.width; ++c) {
      const bool k = mask.at<float>(r, c) != 0.f;
      holes += !k;
      const glm::vec3 t = map.texel(c, r);
      level0.at<cv::Vec4f>(r, c) = k ? cv::Vec4f(t.r, t.g, t.b, 1.f) : cv::Vec4f(0, 0, 0, 0);
    }
  if (holes == 0) return 0;
  if (holes == map.width * map.height) throw InputError("envmap: nothing was covered; there is nothing to fill from");
  std::vector<cv::Mat> pyramid{level0};
  while (pyramid.back().cols > 2 && pyramid.back().rows > 1) pyramid.push_back(pull(pyramid.back()));
  // Push: each level's gaps take the up-sampled coarser level, in proportion to how
  // little the level itself knows there.
  for (int l = int(pyramid.size()) - 2; l >= 0; --l) {
    const cv::Mat up = upsample(pyramid[l + 1], pyramid[l].size());
    cv::Mat& fine = pyramid[l];
    for (int r = 0; r < fine.rows; ++r)
      for (int c = 0; c < fine.cols; ++c) {
        cv::Vec4f& f = fine.at<cv::Vec4f>(r, c);
        const cv::Vec4f& u = up.at<cv::Vec4f>(r, c);
        if (f[3] >= 1.f || u[3] <= 0.f) continue;
        const float need = 1.f - f[3];
        const float s = need / u[3];  // u is premultiplied: normalise its colour
        f += cv::Vec4f(u[0] * s, u[1] * s, u[2] * s, need);
      }
  }
  for (int r = 0; r < map.height; ++r)
    for (int c = 0; c < map.width; ++c) {
      if (mask.at<float>(r, c) != 0.f) continue;
      const cv::Vec4f f = pyramid[0].at<cv::Vec4f>(r, c);
      float* o = &map.rgb[(std::size_t(r) * map.width + c) * 3];
      const float w = f[3] > 0.f ? f[3] : 1.f;
      o[0] = f[0] / w, o[1] = f[1] / w, o[2] = f[2] / w;
    }
  return holes;
}

cv::Mat coverage_image(const cv::Mat& count) {
  cv::Mat counts;
  count.convertTo(counts, CV_32F);
  cv::Mat out(count.size(), CV_8UC3);
  for (int r = 0; r < count.rows; ++r)
    for (int c = 0; c < count.cols; ++c) {
      const float n = counts.at<float>(r, c);
      if (n <= 0.f) {
        out.at<cv::Vec3b>(r, c) = {255, 0, 255};
      } else {
        const auto g = uchar(64 + std::lround(191.0 * std::min(n, 8.f) / 8.0));
        out.at<cv::Vec3b>(r, c) = {g, g, g};
      }
    }
  return out;
}

cv::Mat contact_sheet(const EnvironmentMap& map, const cv::Mat& count) {
  std::vector<float> lum(std::size_t(map.width) * map.height);
  for (std::size_t i = 0; i < lum.size(); ++i)
    lum[i] = 0.2126f * map.rgb[i * 3] + 0.7152f * map.rgb[i * 3 + 1] + 0.0722f * map.rgb[i * 3 + 2];
  std::vector<float> sorted = lum;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const float median = sorted[sorted.size() / 2];
  const float base = median > 0.f ? 0.18f / median : 1.f;
  const float stops[3] = {-4.f, 0.f, 4.f};
  cv::Mat sheet(map.height * 3, map.width, CV_8UC3);
  for (int s = 0; s < 3; ++s) {
    const float k = base * std::exp2(stops[s]);
    for (int r = 0; r < map.height; ++r)
      for (int c = 0; c < map.width; ++c) {
        const glm::vec3 t = map.texel(c, r) * k;
        cv::Vec3b px(uchar(std::lround(linear_to_srgb(t.b) * 255)), uchar(std::lround(linear_to_srgb(t.g) * 255)),
                     uchar(std::lround(linear_to_srgb(t.r) * 255)));
        // Hatch filled holes so nobody mistakes them for measured light.
        if (!count.empty() && count.at<std::uint16_t>(r, c) == 0 && ((r + c) / 4) % 2 == 0)
          px = px / 2 + cv::Vec3b(0, 0, 96);
        sheet.at<cv::Vec3b>(s * map.height + r, c) = px;
      }
  }
  return sheet;
}

}  // namespace lumar::calib
