// Undistortion maps against the forward lens model and cv::undistortPoints, distort_image
// against the forward model, with the real webcam calibration, and the undistortion in
// linear light against remapping the light itself.
#include "lumar/calib/undistortion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/color.h"
#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"
#include "test_paths.h"

namespace lumar::calib {
namespace {

CameraIntrinsics webcam() { return load_camera_file(test::source_dir() / "data/camera/webcam-640x480.yml").intrinsics; }

// Pixel of `camera` where a pinhole pixel (u, v) of `pinhole` lands, by the forward model.
cv::Point2d undistorted_to_distorted(const CameraIntrinsics& camera, const CameraIntrinsics& pinhole, double u,
                                     double v) {
  const glm::dvec3 ray((u - pinhole.cx) / pinhole.fx, (v - pinhole.cy) / pinhole.fy, 1.0);
  const glm::dvec2 p = project_distorted(camera, ray);
  return {p.x, p.y};
}

cv::Point2d precise_undistort(const CameraIntrinsics& camera, const CameraIntrinsics& pinhole, cv::Point2d p) {
  std::vector<cv::Point2d> in{p}, out;
  cv::undistortPoints(in, out, cv::Mat(camera.camera_matrix()), camera.distortion_coefficients(), cv::noArray(),
                      cv::Mat(pinhole.camera_matrix()),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-9));
  return out[0];
}

// Bilinear sample of a CV_32F image at a continuous pixel position.
double sample(const cv::Mat& image, double x, double y) {
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  const auto at = [&](int c, int r) { return double(image.at<float>(r, c)); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// A smooth test pattern, in units of the image it is drawn for (scale = pixels per base pixel).
double pattern(double x, double y) { return 0.5 + 0.25 * std::sin(x / 23.0) + 0.25 * std::cos(y / 17.0 + x / 41.0); }

cv::Mat draw_pattern(const CameraIntrinsics& camera, const CameraIntrinsics& base) {
  // Evaluated in `base` pixel units, so that images for different K show the same scene.
  cv::Mat image(camera.height, camera.width, CV_32F);
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) {
      const double x = (c - camera.cx) / camera.fx * base.fx + base.cx;
      const double y = (r - camera.cy) / camera.fy * base.fy + base.cy;
      image.at<float>(r, c) = float(pattern(x, y));
    }
  return image;
}

TEST(Undistortion, MapsAgreeWithTheLensModelAndOpenCV) {
  const CameraIntrinsics camera = webcam();
  ASSERT_TRUE(camera.has_distortion());
  for (const auto mode : {UndistortedCamera::SameMatrix, UndistortedCamera::CropToValid, UndistortedCamera::KeepAll}) {
    const UndistortionMaps maps = make_undistortion_maps(camera, mode);
    ASSERT_EQ(maps.map_x.type(), CV_32FC1);
    ASSERT_EQ(maps.map_x.size(), cv::Size(640, 480));
    EXPECT_EQ(maps.output.width, 640);
    EXPECT_FALSE(maps.output.has_distortion());
    if (mode == UndistortedCamera::SameMatrix) {
      EXPECT_EQ(maps.output.camera_matrix(), camera.camera_matrix());
    }
    double worst_forward = 0, worst_inverse = 0;
    for (int v = 0; v < 480; v += 37)
      for (int u = 0; u < 640; u += 41) {
        const cv::Point2d source(maps.map_x.at<float>(v, u), maps.map_y.at<float>(v, u));
        worst_forward = std::max(worst_forward, cv::norm(source - undistorted_to_distorted(camera, maps.output, u, v)));
        if (source.x < 0 || source.y < 0 || source.x > 639 || source.y > 479) continue;
        worst_inverse =
            std::max(worst_inverse, cv::norm(precise_undistort(camera, maps.output, source) - cv::Point2d(u, v)));
      }
    EXPECT_LE(worst_forward, 0.01) << int(mode);
    EXPECT_LE(worst_inverse, 0.01) << int(mode);
  }
}

TEST(Undistortion, CropAndKeepAllOutputsDoWhatTheySay) {
  const CameraIntrinsics camera = webcam();
  // SameMatrix: for this barrel lens the calibrated K already crops (every output
  // pixel looks inside the image), and it loses the corners.
  const UndistortionMaps same = make_undistortion_maps(camera);
  double lo = 0, hi = 0;
  cv::minMaxLoc(same.map_x, &lo, &hi);
  EXPECT_GT(lo, 0.0);
  EXPECT_LT(hi, 639.0);
  cv::minMaxLoc(same.map_y, &lo, &hi);
  EXPECT_GT(lo, 0.0);
  EXPECT_LT(hi, 479.0);
  // CropToValid: every output pixel looks inside the distorted image, to within the
  // pixel or so of OpenCV's inner-rectangle estimate.
  const UndistortionMaps crop = make_undistortion_maps(camera, UndistortedCamera::CropToValid);
  double lo_x = 1e9, hi_x = -1e9, lo_y = 1e9, hi_y = -1e9;
  cv::minMaxLoc(crop.map_x, &lo_x, &hi_x);
  cv::minMaxLoc(crop.map_y, &lo_y, &hi_y);
  std::printf("[ measured ] CropToValid looks at x %.3f..%.3f, y %.3f..%.3f of a 640x480 image\n", lo_x, hi_x, lo_y,
              hi_y);
  EXPECT_GE(lo_x, -1.5);
  EXPECT_LE(hi_x, 640.5);
  EXPECT_GE(lo_y, -1.5);
  EXPECT_LE(hi_y, 480.5);
  // KeepAll: every input corner lands inside the output image.
  const UndistortionMaps all = make_undistortion_maps(camera, UndistortedCamera::KeepAll);
  for (const cv::Point2d corner :
       {cv::Point2d(0, 0), cv::Point2d(639, 0), cv::Point2d(0, 479), cv::Point2d(639, 479)}) {
    const cv::Point2d p = precise_undistort(camera, all.output, corner);
    EXPECT_GE(p.x, -1.0);
    EXPECT_LE(p.x, 640.0);
    EXPECT_GE(p.y, -1.0);
    EXPECT_LE(p.y, 480.0);
  }
  // Each step keeps more of the view: a shorter focal length.
  EXPECT_LT(crop.output.fx, camera.fx);
  EXPECT_LT(all.output.fx, crop.output.fx);
}

TEST(Undistortion, DistortImageMatchesTheForwardModel) {
  const CameraIntrinsics camera = webcam();
  const CameraIntrinsics pinhole = camera.without_distortion();
  // A supersampled pinhole image: twice the pixels, pixel centres kept consistent.
  CameraIntrinsics fine = pinhole;
  fine.width *= 2;
  fine.height *= 2;
  fine.fx *= 2;
  fine.fy *= 2;
  fine.cx = 2 * pinhole.cx + 0.5;
  fine.cy = 2 * pinhole.cy + 0.5;
  for (const CameraIntrinsics& source : {pinhole, fine}) {
    const cv::Mat distorted = distort_image(draw_pattern(source, pinhole), source, camera);
    ASSERT_EQ(distorted.size(), cv::Size(640, 480));
    ASSERT_EQ(distorted.type(), CV_32F);
    // Points of the scene land where project_distorted says; compare the pattern there.
    double worst = 0;
    for (double v = 20.3; v < 460; v += 31.7)
      for (double u = 20.6; u < 620; u += 29.9) {
        const cv::Point2d p = undistorted_to_distorted(camera, pinhole, u, v);
        if (p.x < 1 || p.y < 1 || p.x > 638 || p.y > 478) continue;
        worst = std::max(worst, std::abs(sample(distorted, p.x, p.y) - pattern(u, v)));
      }
    EXPECT_LT(worst, 5e-3) << "source " << source.width << "x" << source.height;
  }
}

TEST(Undistortion, DistortThenUndistortRoundTrip) {
  const CameraIntrinsics camera = webcam();
  const CameraIntrinsics pinhole = camera.without_distortion();
  const cv::Mat original = draw_pattern(pinhole, pinhole);
  const cv::Mat distorted = distort_image(original, pinhole, camera);
  const cv::Mat back = undistort_image(distorted, make_undistortion_maps(camera));
  ASSERT_EQ(back.size(), original.size());
  // Interior only: near the borders the distorted image has no data for the round trip.
  const cv::Rect interior(64, 48, 512, 384);
  double worst = 0;
  cv::minMaxLoc(cv::abs(back(interior) - original(interior)), nullptr, &worst);
  EXPECT_LT(worst, 5e-3);
  EXPECT_GT(cv::norm(distorted(interior) - original(interior), cv::NORM_INF), 0.1) << "the lens does change the image";

  // 8-bit images take the same path and agree with the float result to one level.
  cv::Mat original8;
  original.convertTo(original8, CV_8U, 255.0);
  const cv::Mat distorted8 = distort_image(original8, pinhole, camera);
  ASSERT_EQ(distorted8.type(), CV_8U);
  cv::Mat reference;
  distort_image(cv::Mat_<float>(original8), pinhole, camera).convertTo(reference, CV_8U);
  EXPECT_LE(cv::norm(distorted8, reference, cv::NORM_INF), 1.0);
  // And a 3-channel 8-bit image keeps its channels.
  cv::Mat colour;
  cv::merge(std::vector<cv::Mat>{original8, 255 - original8, original8 / 2}, colour);
  const cv::Mat distorted_colour = distort_image(colour, pinhole, camera);
  ASSERT_EQ(distorted_colour.type(), CV_8UC3);
  std::vector<cv::Mat> channels;
  cv::split(distorted_colour, channels);
  EXPECT_LE(cv::norm(channels[0], distorted8, cv::NORM_INF), 0.0);
}

// A response unlike sRGB's: code / 255 to the power 2.2, a different gain per channel.
CameraResponse gamma_response() {
  CameraResponse r;
  for (int k = 0; k < 3; ++k)
    for (int v = 0; v < 256; ++v)
      r.exposure[std::size_t(k)][std::size_t(v)] = (1.0f + 0.5f * float(k)) * std::pow(float(v) / 255.0f, 2.2f);
  return r;
}

// Maps that read every pixel (dx, dy) away from its own place.
UndistortionMaps shifted_maps(const CameraIntrinsics& camera, float dx, float dy) {
  UndistortionMaps maps;
  maps.map_x.create(camera.height, camera.width, CV_32FC1);
  maps.map_y.create(camera.height, camera.width, CV_32FC1);
  for (int r = 0; r < camera.height; ++r)
    for (int c = 0; c < camera.width; ++c)
      maps.map_x.at<float>(r, c) = float(c) + dx, maps.map_y.at<float>(r, c) = float(r) + dy;
  return maps;
}

TEST(Undistortion, InLinearLightMixesLightNotCodes) {
  // Alternate black and white columns, read half a pixel to the right: each output pixel
  // is half of each, which in light is half of white (code 188 in sRGB), not code 128.
  const CameraIntrinsics camera = webcam();
  const UndistortionMaps shifted = shifted_maps(camera, 0.5f, 0.0f);
  cv::Mat columns(camera.height, camera.width, CV_8UC3);
  for (int c = 0; c < camera.width; ++c) columns.col(c).setTo(cv::Scalar::all(c % 2 ? 255 : 0));
  const cv::Mat in_light = undistort_in_linear_light(columns, shifted, srgb_response(1.0));
  const cv::Mat in_codes = undistort_image(columns, shifted);
  const int half_white = int(std::lround(255.0 * linear_to_srgb(0.5f)));
  EXPECT_EQ(half_white, 188);
  for (int c = 10; c < 20; ++c)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(in_light.at<cv::Vec3b>(100, c)[k], half_white) << "column " << c;
      EXPECT_NEAR(in_codes.at<cv::Vec3b>(100, c)[k], 128, 1) << "column " << c;
    }
}

TEST(Undistortion, InLinearLightMatchesRemappingTheLight) {
  // Against the brute force: the image's light remapped as floats, each value's nearest
  // code checked against all 256. Through the real lens, with sRGB and another
  // response.
  const CameraIntrinsics camera = webcam();
  const UndistortionMaps maps = make_undistortion_maps(camera);
  const cv::Mat pattern8 = [&] {
    cv::Mat grey;
    draw_pattern(camera.without_distortion(), camera.without_distortion()).convertTo(grey, CV_8U, 255.0);
    cv::Mat colour;
    cv::merge(std::vector<cv::Mat>{grey, 255 - grey, grey / 2 + 60}, colour);
    return colour;
  }();
  for (const CameraResponse& response : {srgb_response(1.0), gamma_response()}) {
    const cv::Mat out = undistort_in_linear_light(pattern8, maps, response);
    ASSERT_EQ(out.type(), CV_8UC3);
    cv::Mat light;
    cv::remap(linearize(pattern8, response), light, maps.map_x, maps.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    // A code is right when no other code's light is nearer (a tie may go either way).
    int wrong = 0;
    for (int r = 0; r < out.rows; r += 3)
      for (int c = 0; c < out.cols; c += 3)
        for (int k = 0; k < 3; ++k) {
          const float want = light.at<cv::Vec3f>(r, c)[k];
          const float miss = std::abs(response(k, out.at<cv::Vec3b>(r, c)[k]) - want);
          for (int v = 0; v < 256; ++v)
            if (std::abs(response(k, v) - want) < miss) {
              ++wrong;
              break;
            }
        }
    EXPECT_EQ(wrong, 0);
  }
}

TEST(Undistortion, ResamplingVarianceIsTheBilinearMixes) {
  // f(1 - f) per axis: none on pixel centres, 1/4 halfway between, about 1/6 (uniform f's
  // mean) through the real lens, whose offsets cover every fraction.
  const CameraIntrinsics camera = webcam();
  EXPECT_EQ(resampling_variance(shifted_maps(camera, 0.0f, 0.0f)), 0.0);
  EXPECT_NEAR(resampling_variance(shifted_maps(camera, 0.5f, 0.0f)), 0.125, 1e-9) << "halfway in x only: (1/4 + 0) / 2";
  EXPECT_NEAR(resampling_variance(shifted_maps(camera, 0.5f, 0.5f)), 0.25, 1e-9);
  const double lens = resampling_variance(make_undistortion_maps(camera));
  std::printf("the webcam's undistortion: resampling variance %.4f px^2 per axis\n", lens);
  EXPECT_NEAR(lens, 1.0 / 6.0, 0.01);
}

TEST(Undistortion, WrongImageSizeIsAnInputError) {
  const UndistortionMaps maps = make_undistortion_maps(webcam());
  EXPECT_THROW(undistort_image(cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(0)), maps), InputError);
  EXPECT_THROW(undistort_in_linear_light(cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(0)), maps, srgb_response(1.0)),
               InputError);
  CameraIntrinsics broken = webcam();
  broken.fx = 0;
  EXPECT_THROW(make_undistortion_maps(broken), InputError);
}

}  // namespace
}  // namespace lumar::calib
