#include "lumar/calib/sensor_noise.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>

#include "lumar/base/error.h"

namespace lumar::calib {
namespace {

constexpr int kBlock = 8;
// Bins of block means, spaced evenly in log over the range found (down to 1/1000 of the
// brightest): shot noise makes the variance grow with the level, so a bin spanning a
// large ratio of levels mixes blocks of different variances and biases its quantile.
constexpr int kBins = 32;
constexpr double kDarkestBin = 1e-3;
constexpr std::size_t kMinBlocksPerBin = 20;
// Textured blocks only add variance, so a low quantile of a bin's block variances sees
// the flat ones: exactly when the whole bin is flat; when only a fraction f is, it is the
// flat ones' (10 / f)th percentile (sigma +13 % at f = 0.3, simulated). The 10th is barely
// less precise than the 20th (the density there is still high) and twice as robust.
constexpr double kQuantile = 0.1;
constexpr double kQuantileZ = -1.2816;  // the standard normal's 10th percentile
// A bin's quantile, divided by the fraction below, has a relative standard error of
// 0.53 / sqrt(blocks) (that of a chi-square quantile). A bin further above the fit than
// 3 such errors and 5 % (room for a camera that is not quite linear) is mostly texture,
// and is left out.
constexpr double kQuantileError = 0.53;
constexpr double kModelTolerance = 0.05;
// r = x - (n + s + e + w) / 4 is zero on any plane; on white noise its variance is
// (1 + 4/16) sigma^2.
constexpr double kHighPassGain = 1.25;
// The 64 residuals of a block are correlated (-0.4 with 4-neighbours, 0.1 diagonally,
// 0.05 two apart), so their variance has 64^2 / sum(rho^2) = 40 degrees of freedom
// (Satterthwaite; a simulation of white noise agrees, as does its 10th percentile).
constexpr double kDegreesOfFreedom = 40.0;

struct Block {
  float mean, variance;  // linear; the variance with the 8-bit rounding's
};

// The 10th percentile of sigma^2 chi2_nu / nu in units of sigma^2 (Wilson-Hilferty): the
// low quantile of a bin of flat blocks divided by it is the bin's variance.
double quantile_fraction() {
  const double a = 2.0 / (9.0 * kDegreesOfFreedom);
  return std::pow(1.0 - a + kQuantileZ * std::sqrt(a), 3.0);
}

// 8-bit rounding adds (dlinear/dcode)^2 / 12 of variance at a level (once the noise
// spans a code or more); the caller wants the sensor's, so it is subtracted.
double rounding_variance(const std::array<float, 256>& table, double linear) {
  const auto code = std::lower_bound(table.begin(), table.end(), float(linear)) - table.begin();
  const std::size_t v = std::size_t(std::clamp<std::ptrdiff_t>(code, 1, 254));
  const double slope = (table[v + 1] - table[v - 1]) / 2.0;
  return slope * slope / 12.0;
}

// Appends the unclipped kBlock x kBlock blocks of one frame, per channel. Blocks start
// one pixel in, so that every residual has its four neighbours. Works a strip of blocks
// at a time: a whole linear frame would cost more in fresh pages than in arithmetic.
void measure_blocks(const cv::Mat& frame, const CameraResponse& response, std::array<std::vector<Block>, 3>& blocks) {
  const int columns = (frame.cols - 2) / kBlock, rows = (frame.rows - 2) / kBlock;
  const cv::Mat cross = cv::getStructuringElement(cv::MORPH_CROSS, {3, 3});
  struct Sums {
    double linear = 0, r = 0, r2 = 0;
    bool clipped = false;
  };
  std::vector<Sums> row(std::size_t(std::max(columns, 0)) * 3);
  for (int by = 0; by < rows; ++by) {
    const cv::Mat strip = frame.rowRange(by * kBlock, (by + 1) * kBlock + 2);
    const cv::Mat linear = linearize(strip, response);
    // Clipped codes and their 4-neighbours (whose residuals they enter), per channel.
    cv::Mat clipped = (strip == 0) | (strip == 255);
    cv::dilate(clipped, clipped, cross);
    std::fill(row.begin(), row.end(), Sums{});
    for (int y = 1; y <= kBlock; ++y) {
      const float *up = linear.ptr<float>(y - 1), *p = linear.ptr<float>(y), *down = linear.ptr<float>(y + 1);
      const uchar* bad = clipped.ptr<uchar>(y);
      for (int bx = 0; bx < columns; ++bx)
        for (int c = 0; c < 3; ++c) {
          float s = 0, sr = 0, sr2 = 0;
          uchar any_bad = 0;
          for (int i = 3 * (1 + bx * kBlock) + c, end = i + 3 * kBlock; i < end; i += 3) {
            const float r = p[i] - 0.25f * (up[i] + down[i] + p[i - 3] + p[i + 3]);
            s += p[i], sr += r, sr2 += r * r;
            any_bad |= bad[i];
          }
          Sums& b = row[std::size_t(bx) * 3 + std::size_t(c)];
          b.linear += s, b.r += sr, b.r2 += sr2;
          b.clipped |= any_bad != 0;
        }
    }
    // Divided by n, not n - 1: the block's mean residual is nearly noise-free (the high-pass
    // summed over a block leaves only its boundary), so removing it costs no variance.
    constexpr double n = kBlock * kBlock;
    for (int bx = 0; bx < columns; ++bx)
      for (std::size_t c = 0; c < 3; ++c) {
        const Sums& b = row[std::size_t(bx) * 3 + c];
        if (!b.clipped) blocks[c].push_back({float(b.linear / n), float((b.r2 - b.r * b.r / n) / n / kHighPassGain)});
      }
  }
}

struct Point {
  double x, y, rounding, count;  // level, sensor variance, rounding variance, blocks
};

// Weighted least squares of y = a + b x with a, b >= 0: the free solution, or else the
// better of the two with one coefficient at zero.
std::array<double, 2> fit_nonnegative(const std::vector<Point>& points, const std::vector<double>& w) {
  double sw = 0, sx = 0, sxx = 0, sy = 0, sxy = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& p = points[i];
    sw += w[i], sx += w[i] * p.x, sxx += w[i] * p.x * p.x, sy += w[i] * p.y, sxy += w[i] * p.x * p.y;
  }
  const double det = sw * sxx - sx * sx;
  if (det > 0) {
    const double b = (sw * sxy - sx * sy) / det, a = (sy - b * sx) / sw;
    if (a >= 0 && b >= 0) return {a, b};
  }
  const auto cost = [&](double a, double b) {
    double e = 0;
    for (std::size_t i = 0; i < points.size(); ++i) e += w[i] * std::pow(points[i].y - a - b * points[i].x, 2);
    return e;
  };
  const double a_only = sw > 0 ? std::max(0.0, sy / sw) : 0.0, b_only = sxx > 0 ? std::max(0.0, sxy / sxx) : 0.0;
  if (cost(a_only, 0) <= cost(0, b_only)) return {a_only, 0.0};
  return {0.0, b_only};
}

// Fits one channel's blocks; `used` gets the blocks in the bins the fit kept.
std::array<double, 2> fit_channel(std::vector<Block>& blocks, const std::array<float, 256>& table, std::size_t channel,
                                  std::size_t frames, std::size_t& used) {
  float high = 0;
  for (const Block& b : blocks) high = std::max(high, b.mean);
  const double low = kDarkestBin * high, step = std::log(1.0 / kDarkestBin) / kBins;
  std::vector<std::vector<Block>> bins(kBins);
  for (const Block& b : blocks)
    bins[std::size_t(std::min(kBins - 1, b.mean > low ? int(std::log(b.mean / low) / step) : 0))].push_back(b);

  const double fraction = quantile_fraction();
  std::vector<Point> points;
  for (std::vector<Block>& bin : bins) {
    if (bin.size() < kMinBlocksPerBin) continue;
    const std::size_t k = std::size_t(kQuantile * double(bin.size()));
    std::nth_element(bin.begin(), bin.begin() + std::ptrdiff_t(k), bin.end(),
                     [](const Block& a, const Block& b) { return a.variance < b.variance; });
    double mean = 0;
    for (const Block& b : bin) mean += b.mean;
    mean /= double(bin.size());
    const double rounding = rounding_variance(table, mean);
    points.push_back({mean, bin[k].variance / fraction - rounding, rounding, double(bin.size())});
  }
  if (points.size() < 2)
    throw InputError("sensor noise: only " + std::to_string(blocks.size()) + " unclipped 8x8 patches in channel " +
                     std::to_string(channel) + " of " + std::to_string(frames) + " frame(s), in " +
                     std::to_string(points.size()) + " brightness level(s) with " + std::to_string(kMinBlocksPerBin) +
                     " or more; give more frames, or frames with unclipped smooth areas at several brightness levels");

  // A quantile's error is proportional to the variance it measures (the sensor's plus
  // the rounding), over sqrt(count): weight count / variance^2, the variance from the
  // previous fit (at first, the points').
  const auto weight = [](const Point& p, double variance) { return p.count / std::pow(std::max(variance, 1e-30), 2); };
  std::vector<double> w(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    w[i] = weight(points[i], std::max(points[i].y, 0.0) + points[i].rounding);
  std::array<double, 2> fit{};
  for (int iteration = 0; iteration < 6; ++iteration) {
    fit = fit_nonnegative(points, w);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      const double predicted = fit[0] + fit[1] * p.x + p.rounding;
      const double excess = std::max(kModelTolerance, 3 * kQuantileError / std::sqrt(p.count));
      w[i] = p.y + p.rounding > (1 + excess) * predicted ? 0.0 : weight(p, predicted);
    }
  }
  used = 0;
  for (std::size_t i = 0; i < points.size(); ++i) used += w[i] > 0 ? std::size_t(points[i].count) : 0;
  return fit;
}

}  // namespace

double SensorNoise::sigma(int channel, double linear) const {
  const std::size_t c = std::size_t(channel);
  return std::sqrt(std::max(0.0, read_variance[c] + shot_gain[c] * std::max(linear, 0.0)));
}

SensorNoise estimate_sensor_noise(const std::vector<cv::Mat>& frames_bgr8, const CameraResponse& response) {
  if (frames_bgr8.empty()) throw InputError("sensor noise: no frames; give at least one video frame");
  std::array<std::vector<Block>, 3> blocks;
  for (std::size_t i = 0; i < frames_bgr8.size(); ++i) {
    const cv::Mat& frame = frames_bgr8[i];
    if (frame.empty() || frame.type() != CV_8UC3)
      throw InputError("sensor noise: frame " + std::to_string(i) +
                       " is empty or not 8-bit 3-channel; give the video's colour frames");
    measure_blocks(frame, response, blocks);
  }
  SensorNoise noise;
  noise.patches = std::numeric_limits<std::size_t>::max();
  for (std::size_t c = 0; c < 3; ++c) {
    std::size_t used = 0;
    const auto fit = fit_channel(blocks[c], response.exposure[c], c, frames_bgr8.size(), used);
    noise.read_variance[c] = fit[0];
    noise.shot_gain[c] = fit[1];
    noise.patches = std::min(noise.patches, used);
  }
  return noise;
}

}  // namespace lumar::calib
