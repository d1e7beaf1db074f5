// Camera response and HDR merge against a synthetic bracket of a real HDR environment
// map, made with a known analytic response, 8-bit quantisation, clipping and noise.
#include "lumar/calib/camera_response.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/scene/envmap.h"
#include "test_paths.h"

namespace lumar::calib {
namespace {

// The camera of the synthetic bracket: gamma 2.2 after a soft highlight knee,
// x = 1 maps to 255. Analytic inverse below.
double applied_curve(double x) { return std::pow(1.25 * x / (1.0 + 0.25 * x), 1.0 / 2.2); }
double applied_inverse(double z) {
  const double y = std::pow(z / 255.0, 2.2);
  return y / (1.25 - 0.25 * y);
}

struct Bracket {
  cv::Mat radiance;  // CV_32FC3, the truth
  std::vector<cv::Mat> images;
  std::vector<double> times{1.0 / 256, 1.0 / 64, 1.0 / 16, 1.0 / 4, 1.0};
};

const Bracket& bracket() {
  static const Bracket b = [] {
    Bracket out;
    const EnvironmentMap map = load_environment_map(test::shared_dir() / "data/envmaps/interior.exr");
    cv::Mat full(map.height, map.width, CV_32FC3, const_cast<float*>(map.rgb.data()));
    cv::resize(full, out.radiance, cv::Size(256, 128), 0, 0, cv::INTER_AREA);
    out.radiance = cv::max(out.radiance, 1e-6f);
    // Put the median at 18 % grey in the middle exposure.
    std::vector<float> values(out.radiance.begin<float>(), out.radiance.end<float>());
    std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
    out.radiance *= 0.18 * 16.0 / values[values.size() / 2];
    cv::RNG rng(12345);
    for (double t : out.times) {
      cv::Mat image(out.radiance.size(), CV_8UC3);
      for (int y = 0; y < image.rows; ++y)
        for (int x = 0; x < image.cols; ++x)
          for (int c = 0; c < 3; ++c) {
            const double z = 255.0 * applied_curve(out.radiance.at<cv::Vec3f>(y, x)[c] * t) + rng.gaussian(0.5);
            image.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uchar>(std::lround(z));
          }
      out.images.push_back(image);
    }
    return out;
  }();
  return b;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * double(v.size())))];
}

// Debevec's solve takes about 2 s; every test shares one recovery.
const CameraResponse& recovered() {
  static const CameraResponse r = recover_response_debevec(bracket().images, bracket().times);
  return r;
}

TEST(CameraResponse, DebevecRecoversTheAppliedResponseUpToScale) {
  const CameraResponse& r = recovered();
  // Within 16..245 the hat weight is at least 10 of 127; toward the ends Debevec is
  // constrained mostly by its smoothness term and drifts (reported, not asserted).
  double max_dev = 0.0, max_dev_ends = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int v = 1; v < 256; ++v) EXPECT_GT(r(c, v), r(c, v - 1)) << "channel " << c << " value " << v;
    for (int v = 1; v <= 254; ++v) {
      const double truth = applied_inverse(v) / applied_inverse(128);
      const double dev = std::abs(r(c, v) / truth - 1.0);
      double& worst = v >= 16 && v <= 245 ? max_dev : max_dev_ends;
      worst = std::max(worst, dev);
    }
  }
  std::printf(
      "[ response ] max relative deviation from the applied response: %.2f %% (values 16..245), "
      "%.2f %% (1..15, 246..254)\n",
      100 * max_dev, 100 * max_dev_ends);
  EXPECT_LT(max_dev, 0.04);
}

TEST(CameraResponse, MergedBracketMatchesTheTrueRadianceWithin5Percent) {
  const Bracket& b = bracket();
  const cv::Mat hdr = merge_hdr(b.images, b.times, recovered());
  // Where some exposure neither clips nor goes black (noise-free value in 2..253).
  std::vector<double> ratios;
  std::vector<std::pair<double, double>> pairs;  // merged, true
  for (int y = 0; y < hdr.rows; ++y)
    for (int x = 0; x < hdr.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double truth = b.radiance.at<cv::Vec3f>(y, x)[c];
        bool usable = false;
        for (double t : b.times) {
          const double z = 255.0 * applied_curve(truth * t);
          usable |= z >= 2.0 && z <= 253.0;
        }
        if (!usable) continue;
        const double merged = hdr.at<cv::Vec3f>(y, x)[c];
        ratios.push_back(truth / merged);
        pairs.emplace_back(merged, truth);
      }
  ASSERT_GT(pairs.size(), hdr.total() * 3 / 2) << "the bracket should cover most of the map";
  const double scale = percentile(ratios, 0.5);
  std::vector<double> errors;
  for (auto [merged, truth] : pairs) errors.push_back(std::abs(scale * merged - truth) / truth);
  const double median = percentile(errors, 0.5), p95 = percentile(errors, 0.95), p99 = percentile(errors, 0.99);
  std::printf("[ hdr merge ] %zu of %zu samples usable; relative error median %.2f %%, p95 %.2f %%, p99 %.2f %%\n",
              pairs.size(), hdr.total() * 3, 100 * median, 100 * p95, 100 * p99);
  EXPECT_LT(median, 0.02);
  EXPECT_LT(p95, 0.05);
  EXPECT_LT(p99, 0.05);
}

TEST(CameraResponse, PixelsClippedInEveryExposureTakeTheNearestExposure) {
  const CameraResponse r = srgb_response();
  const std::vector<double> times{0.01, 0.1};
  std::vector<cv::Mat> images{cv::Mat(1, 2, CV_8UC3, cv::Scalar(255, 255, 0)),
                              cv::Mat(1, 2, CV_8UC3, cv::Scalar(255, 255, 0))};
  images[0].at<cv::Vec3b>(0, 1) = images[1].at<cv::Vec3b>(0, 1) = cv::Vec3b(0, 0, 0);
  const cv::Mat hdr = merge_hdr(images, times, r);
  EXPECT_FLOAT_EQ(hdr.at<cv::Vec3f>(0, 0)[0], 1.f / 0.01f);  // white: lower bound from the shortest
  EXPECT_FLOAT_EQ(hdr.at<cv::Vec3f>(0, 1)[0], 0.f);          // black: the longest exposure's zero
}

TEST(CameraResponse, MergeWithTheExactResponseIsWithinQuantisation) {
  // The merge alone, with the true response: isolates it from Debevec's recovery.
  const Bracket& b = bracket();
  CameraResponse exact;
  for (int c = 0; c < 3; ++c)
    for (int v = 0; v < 256; ++v) exact.exposure[size_t(c)][size_t(v)] = float(applied_inverse(v));
  const cv::Mat hdr = merge_hdr(b.images, b.times, exact);
  std::vector<double> errors;
  for (int y = 0; y < hdr.rows; ++y)
    for (int x = 0; x < hdr.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double truth = b.radiance.at<cv::Vec3f>(y, x)[c];
        if (255.0 * applied_curve(truth * b.times.front()) > 253.0 || 255.0 * applied_curve(truth) < 2.0) continue;
        errors.push_back(std::abs(hdr.at<cv::Vec3f>(y, x)[c] - truth) / truth);
      }
  const double p95 = percentile(errors, 0.95);
  std::printf("[ hdr merge, exact response ] relative error median %.2f %%, p95 %.2f %%\n",
              100 * percentile(errors, 0.5), 100 * p95);
  EXPECT_LT(p95, 0.05);
}

TEST(CameraResponse, LinearizeWithSrgbResponseInvertsLinearToSrgb) {
  const CameraResponse r = srgb_response();
  cv::Mat values(1, 256, CV_8UC3);
  for (int v = 0; v < 256; ++v) values.at<cv::Vec3b>(v) = cv::Vec3b(uchar(v), uchar(v), uchar(v));
  const cv::Mat linear = linearize(values, r);
  ASSERT_EQ(linear.type(), CV_32FC3);
  for (int v = 0; v < 256; ++v)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(255.f * linear_to_srgb(linear.at<cv::Vec3f>(v)[c]), float(v), 1e-2f);
  // Encoding any linear value and decoding it lands within half an 8-bit step.
  double worst_steps = 0.0;
  for (int i = 0; i <= 1000; ++i) {
    const float x = float(i) / 1000.f;
    const uchar z = cv::saturate_cast<uchar>(std::lround(255.f * linear_to_srgb(x)));
    const cv::Mat one(1, 1, CV_8UC3, cv::Scalar(z, z, z));
    const float back = linearize(one, r).at<cv::Vec3f>(0)[1];
    worst_steps = std::max(worst_steps, std::abs(255.0 * (linear_to_srgb(back) - linear_to_srgb(x))));
  }
  EXPECT_LE(worst_steps, 0.5 + 1e-3);
  // The gain divides: video linear value per unit of radiance.
  EXPECT_NEAR(srgb_response(2.0)(1, 200), srgb_to_linear(200.f / 255.f) / 2.f, 1e-7f);
}

TEST(CameraResponse, SaveLoadRoundTripAndBadFiles) {
  test::Scratch scratch("camera_response");
  const auto path = scratch.dir / "response.json";
  const CameraResponse& r = recovered();
  save_camera_response(path, r);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
  const CameraResponse back = load_camera_response(path);
  for (int c = 0; c < 3; ++c)
    for (int v = 0; v < 256; ++v) EXPECT_EQ(back(c, v), r(c, v));

  auto expect_input_error = [&](const std::string& text) {
    const auto bad = scratch.dir / "bad.json";
    std::ofstream(bad) << text;
    try {
      load_camera_response(bad);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    }
  };
  expect_input_error("{ not json");
  expect_input_error(R"({"format": "something-else", "channels": []})");
  expect_input_error(R"({"format": 3, "channels": []})");
  expect_input_error("[1, 2, 3]");
  expect_input_error(R"({"format": "lumar-camera-response", "channels": [[1, 2], [1, 2], [1, 2]]})");
  std::vector<float> decreasing(256, 1.f);
  decreasing[100] = 0.5f;
  expect_input_error(
      nlohmann::json{{"format", "lumar-camera-response"}, {"channels", {decreasing, decreasing, decreasing}}}.dump());
  EXPECT_THROW(load_camera_response(scratch.dir / "missing.json"), InputError);
}

TEST(CameraResponse, BadBracketsAreInputErrors) {
  const Bracket& b = bracket();
  const CameraResponse r = srgb_response();
  const std::vector<cv::Mat> one{b.images[0]};
  EXPECT_THROW(recover_response_debevec(one, {1.0}), InputError);
  EXPECT_THROW(merge_hdr(one, {1.0}, r), InputError);
  cv::Mat small;
  cv::resize(b.images[1], small, cv::Size(128, 64));
  EXPECT_THROW(recover_response_debevec({b.images[0], small}, {1.0, 2.0}), InputError);
  EXPECT_THROW(merge_hdr({b.images[0], small}, {1.0, 2.0}, r), InputError);
  const std::vector<cv::Mat> two{b.images[0], b.images[1]};
  EXPECT_THROW(recover_response_debevec(two, {1.0, 0.0}), InputError);
  EXPECT_THROW(merge_hdr(two, {-1.0, 1.0}, r), InputError);
  EXPECT_THROW(merge_hdr(two, {1.0, std::nan("")}, r), InputError);
  EXPECT_THROW(merge_hdr(two, {1.0}, r), InputError);
  cv::Mat grey;
  cv::cvtColor(b.images[0], grey, cv::COLOR_BGR2GRAY);
  EXPECT_THROW(merge_hdr({grey, grey}, {1.0, 2.0}, r), InputError);
  EXPECT_THROW(srgb_response(0.0), InputError);
}

}  // namespace
}  // namespace lumar::calib
