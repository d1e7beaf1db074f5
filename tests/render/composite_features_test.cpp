// What makes rendered pixels look like the camera's (gl::CompositeFeatures), each against
// an analytic expectation and switched off: the sensor's noise statistics, the coverage
// that antialiasing gives a disc's outline, the Gaussian profile of a blurred edge, and the
// self-occlusion's open share and bent normal, and the exact lights the object blocks
// itself, against the CPU's IrradianceVolume::evaluate; the undistortion's resampling
// after the clipping; the motion blur against the frames drawn one instant at a time.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/constants.h"
#include "lumar/base/error.h"
#include "lumar/capture/chroma_sampling.h"
#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/room_radiance.h"
#include "lumar/render/renderer.h"
#include "render_test_util.h"

namespace lumar::test {
namespace {

constexpr gl::CompositeFeatures kNone = gl::CompositeFeatures::none();

// A camera looking down -z at a quad of `half` half-width at z = -2, lit to linear `value`.
struct FlatObject {
  explicit FlatObject(float value, float half = 0.5f, glm::vec3 centre = {0, 0, -2}) {
    renderer = std::make_unique<gl::Renderer>(camera);
    id = renderer->add_object(make_quad(centre, {half, 0, 0}, {0, half, 0}, {0, 0, 1}));
    renderer->set_object_material(id, glm::vec3(1.0f), uniform_sh(value));
  }
  CameraIntrinsics camera = make_camera(160, 120, 150, 150, 79.5, 59.5);
  Pose pose = look_at({0, 0, 0}, {0, 0, -1});
  std::unique_ptr<gl::Renderer> renderer;
  int id = 0;
};

TEST(CompositeFeatures, NoiseHasTheSensorsVarianceOnRenderedPixelsOnly) {
  headless_context();
  FlatObject flat(0.3f);
  gl::VideoRadiometry radiometry;
  radiometry.noise_read_variance = {4e-4f, 1e-4f, 2.5e-5f};
  radiometry.noise_shot_gain = {0.0f, 2e-3f, 4e-3f};
  flat.renderer->set_video_radiometry(radiometry);
  flat.renderer->set_features({.antialiasing = false, .self_occlusion = false, .noise = true, .blur = false});
  const cv::Mat video(120, 160, CV_8UC3, cv::Scalar(40, 80, 120));
  const cv::Mat first = flat.renderer->render_overlay(video, flat.pose, 1.0);
  const cv::Mat second = flat.renderer->render_overlay(video, flat.pose, 1.0);
  const cv::Mat mask = flat.renderer->render_object_mask(flat.pose);
  ASSERT_GT(cv::countNonZero(mask), 4000);
  cv::Mat diff;
  cv::absdiff(first, video, diff);
  cv::Mat background_changed;
  cv::reduce(diff.reshape(1, int(diff.total())), background_changed, 1, cv::REDUCE_MAX);
  EXPECT_EQ(cv::countNonZero(background_changed.reshape(1, 120) & ~mask), 0) << "the video is the camera's already";
  cv::Scalar mean, sd;
  cv::meanStdDev(linear_of(first), mean, sd, mask);
  for (int k = 0; k < 3; ++k) {
    const double expected = std::sqrt(radiometry.noise_read_variance[k] + radiometry.noise_shot_gain[k] * 0.3);
    // 8-bit rounding adds (dlinear/dcode)^2 / 12: about 0.0005 near 0.3 (sRGB), a few % here.
    EXPECT_NEAR(sd[k], expected, 0.08 * expected) << "channel " << k;
    EXPECT_NEAR(mean[k], 0.3, 0.01);
  }
  EXPECT_GT(cv::norm(first, second, cv::NORM_L1, mask), 0.0) << "a new draw every frame";
  // With the codec's chroma (4:2:0) the noise comes after it, as it was measured on the
  // footage: the same variance per channel, not its chroma's share averaged over 2×2.
  radiometry.chroma_horizontal = radiometry.chroma_vertical = 2;
  flat.renderer->set_video_radiometry(radiometry);
  cv::Mat inner;
  cv::erode(mask, inner, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(9, 9)));
  cv::meanStdDev(linear_of(flat.renderer->render_overlay(video, flat.pose, 1.0)), mean, sd, inner);
  for (int k = 0; k < 3; ++k) {
    const double expected = std::sqrt(radiometry.noise_read_variance[k] + radiometry.noise_shot_gain[k] * 0.3);
    EXPECT_NEAR(sd[k], expected, 0.08 * expected) << "channel " << k << " with chroma";
  }
  radiometry.chroma_horizontal = radiometry.chroma_vertical = 1;
  flat.renderer->set_video_radiometry(radiometry);

  flat.renderer->set_features(kNone);
  cv::meanStdDev(linear_of(flat.renderer->render_overlay(video, flat.pose, 1.0)), mean, sd, mask);
  EXPECT_LT(sd[0] + sd[1] + sd[2], 1e-6);
}

TEST(CompositeFeatures, AntialiasingGivesTheOutlineItsCoverage) {
  headless_context();
  const CameraIntrinsics camera = make_camera(320, 240, 300, 300, 159.5, 119.5);
  const Pose pose = look_at({0, 0, 0}, {0, 0, -1});
  gl::Renderer renderer(camera);
  const float radius = 0.3f;
  const int sphere = renderer.add_object(make_sphere({0, 0, -2}, radius, 256, 128));
  renderer.set_object_material(sphere, glm::vec3(1.0f), uniform_sh(0.5));
  const cv::Mat black(240, 320, CV_8UC3, cv::Scalar::all(0));
  // A sphere straight ahead is a disc of radius f r / sqrt(d^2 - r^2).
  const double disc_radius = 300.0 * radius / std::sqrt(4.0 - radius * radius);
  const double area = std::numbers::pi * disc_radius * disc_radius;
  const auto measure = [&](bool antialiasing, int* partial) {
    renderer.set_features({.antialiasing = antialiasing, .self_occlusion = false, .noise = false, .blur = false});
    const cv::Mat out = linear_of(renderer.render_overlay(black, pose, 1.0));
    *partial = 0;
    for (int r = 0; r < out.rows; ++r)
      for (int c = 0; c < out.cols; ++c)
        *partial += out.at<cv::Vec3f>(r, c)[1] > 0.02f && out.at<cv::Vec3f>(r, c)[1] < 0.48f;
    // Covered area in pixels: the sum over the inside's value (0.5 after 8-bit rounding).
    return cv::sum(out)[1] / out.at<cv::Vec3f>(120, 160)[1];
  };
  int partial_aa = 0, partial_plain = 0;
  const double covered_aa = measure(true, &partial_aa), covered_plain = measure(false, &partial_plain);
  std::printf("disc %.1f px: antialiased %.1f px (%d partly covered), plain %.1f px (%d)\n", area, covered_aa,
              partial_aa, covered_plain, partial_plain);
  EXPECT_NEAR(covered_aa, area, 0.003 * area);
  EXPECT_GT(partial_aa, int(2.0 * disc_radius * std::numbers::pi * 0.5));  // along most of the outline
  EXPECT_EQ(partial_plain, 0);
}

TEST(CompositeFeatures, BlurGivesAnEdgeTheCamerasGaussianProfile) {
  headless_context();
  // A quad whose left edge is at x = 0, the boundary between columns 79 and 80.
  FlatObject flat(0.5f, 1.0f, {1.0f, 0.0f, -2.0f});
  gl::VideoRadiometry radiometry;
  radiometry.blur_sigma_px = 1.5;
  flat.renderer->set_video_radiometry(radiometry);
  flat.renderer->set_features({.antialiasing = true, .self_occlusion = false, .noise = false, .blur = true});
  const cv::Mat black(120, 160, CV_8UC3, cv::Scalar::all(0));
  const cv::Mat out = linear_of(flat.renderer->render_overlay(black, flat.pose, 1.0));
  // The pixel's own area (a box, variance 1/12) and the Gaussian: a normal CDF across the edge.
  const double sigma = std::sqrt(1.5 * 1.5 + 1.0 / 12.0);
  double worst = 0;
  for (int c = 72; c <= 88; ++c) {
    const double expected = 0.5 * 0.5 * std::erfc(-(c - 79.5) / (sigma * std::sqrt(2.0)));
    worst = std::max(worst, std::abs(out.at<cv::Vec3f>(60, c)[1] - expected));
  }
  std::printf("blurred edge: worst |profile - normal CDF| %.4f of 0.5\n", worst);
  EXPECT_LT(worst, 0.012);
  EXPECT_EQ(out.at<cv::Vec3f>(60, 40)[1], 0.0f) << "beyond the blur the video stays as it was";

  flat.renderer->set_features(kNone);
  const cv::Mat sharp = linear_of(flat.renderer->render_overlay(black, flat.pose, 1.0));
  EXPECT_EQ(sharp.at<cv::Vec3f>(60, 79)[1], 0.0f);
  EXPECT_NEAR(sharp.at<cv::Vec3f>(60, 80)[1], 0.5f, 0.005f);
}

TEST(CompositeFeatures, TheUndistortionsResamplingFollowsTheClipping) {
  // An object four times brighter than white whose left edge is the boundary between
  // columns 79 and 80, and a map that reads the video half a pixel off both ways: the
  // undistortion mixed the video's pixels by (1/2, 1/2), a variance of 1/4 per axis, so
  // rendered pixels get the 3-tap (1/8, 3/4, 1/8) of that variance, of their clipped light.
  headless_context();
  FlatObject flat(4.0f, 1.0f, {1.0f, 0.0f, -2.0f});
  cv::Mat map_x(120, 160, CV_32FC1), map_y(120, 160, CV_32FC1);
  for (int r = 0; r < 120; ++r)
    for (int c = 0; c < 160; ++c) map_x.at<float>(r, c) = float(c) + 0.5f, map_y.at<float>(r, c) = float(r) + 0.5f;
  flat.renderer->set_undistortion_map(map_x, map_y);
  flat.renderer->set_features({.antialiasing = false, .self_occlusion = false, .noise = false, .blur = true});
  const cv::Mat black(120, 160, CV_8UC3, cv::Scalar::all(0));
  const cv::Mat out = linear_of(flat.renderer->render_overlay(black, flat.pose, 1.0));
  const auto at = [&](const cv::Mat& image, int c) { return image.at<cv::Vec3f>(60, c)[1]; };
  std::printf("resampled after clipping: columns 78-81 %.4f %.4f %.4f %.4f\n", at(out, 78), at(out, 79), at(out, 80),
              at(out, 81));
  EXPECT_EQ(at(out, 78), 0.0f);
  // An eighth of white, not of the unclipped 4 (which would be white itself).
  EXPECT_NEAR(at(out, 79), 0.125f, 0.004f);
  EXPECT_NEAR(at(out, 80), 0.875f, 0.01f);
  EXPECT_NEAR(at(out, 81), 1.0f, 1e-6f);

  // Switched off with the blur, and nothing to do without an undistortion map.
  flat.renderer->set_features(kNone);
  const cv::Mat off = linear_of(flat.renderer->render_overlay(black, flat.pose, 1.0));
  EXPECT_EQ(at(off, 79), 0.0f);
  EXPECT_NEAR(at(off, 80), 1.0f, 1e-6f);
  FlatObject unmapped(4.0f, 1.0f, {1.0f, 0.0f, -2.0f});
  unmapped.renderer->set_features({.antialiasing = false, .self_occlusion = false, .noise = false, .blur = true});
  EXPECT_EQ(at(linear_of(unmapped.renderer->render_overlay(black, unmapped.pose, 1.0)), 79), 0.0f);
}

TEST(CompositeFeatures, SelfOcclusionLightsTheOpenShareFromTheBentNormal) {
  headless_context();
  FlatObject flat(0.0f);
  // Light from the upper hemisphere only: E(up) = pi, E(facing the camera, +z) = pi / 2.
  SH9 sky;
  sky.coefficients[0] = glm::dvec3(0.282095 * 2.0 * kPi);  // a unit upper hemisphere: L00
  sky.coefficients[1] = glm::dvec3(0.488603 * kPi);        // and L1-1 (y)
  flat.renderer->set_object_material(flat.id, glm::vec3(1.0f), sky);
  const cv::Mat black(120, 160, CV_8UC3, cv::Scalar::all(0));
  const auto centre_value = [&] {
    return linear_of(flat.renderer->render_overlay(black, flat.pose, 1.0)).at<cv::Vec3f>(60, 80)[1];
  };
  flat.renderer->set_features(kNone);
  const float plain = centre_value();
  // Half open, bent straight up: E(up) / 2 = E(+z).
  std::vector<VertexOcclusion> occlusion(4, VertexOcclusion{{0, 1, 0}, 0.5f});
  flat.renderer->set_object_self_occlusion(flat.id, occlusion);
  flat.renderer->set_features({.antialiasing = false, .self_occlusion = true, .noise = false, .blur = false});
  const float bent_up = centre_value();
  // Half open along its own normal: half of E(+z).
  for (auto& o : occlusion) o.bent_normal = {0, 0, 1};
  flat.renderer->set_object_self_occlusion(flat.id, occlusion);
  const float half = centre_value();
  std::printf("self-occlusion: plain %.4f, half open bent up %.4f, half open %.4f\n", plain, bent_up, half);
  EXPECT_NEAR(plain, 0.5f, 0.01f);
  EXPECT_NEAR(bent_up, plain, 0.01f);
  EXPECT_NEAR(half, 0.5f * plain, 0.006f);
  EXPECT_THROW(flat.renderer->set_object_self_occlusion(flat.id, std::vector<VertexOcclusion>(3)), InputError);
}

TEST(CompositeFeatures, TheObjectsOwnShadowDarkensTheExactLightsAtTheNormal) {
  headless_context();
  // A dim sky and a sun texel block that the quad (facing +z) sees: a distant volume
  // whose exact lights hold the sun.
  const EnvironmentMap map = dim_sky_with_sun();
  const VolumeSettings settings = volume_settings_for("volume");
  const IrradianceVolume volume = IrradianceVolume::build_distant(RoomRadiance(map, settings.radiance), settings);
  ASSERT_FALSE(volume.lights.empty());
  FlatObject flat(0.0f);
  flat.renderer->set_irradiance_volume(&volume);
  const double exposure = 0.05;
  const cv::Mat black(120, 160, CV_8UC3, cv::Scalar::all(0));
  const auto centre_value = [&] {
    return linear_of(flat.renderer->render_overlay(black, flat.pose, exposure)).at<cv::Vec3f>(60, 80)[1];
  };
  const glm::dvec3 p(0, 0, -2), n(0, 0, 1), up(0, 1, 0);
  const auto expected = [&](const glm::dvec3& bent, double open, double lights) {
    return float(volume.evaluate(p, bent, n, open, lights).g * exposure / kPi);
  };
  // Half open, bent up, and the sun's light half blocked, then wholly, then not at all.
  flat.renderer->set_object_self_occlusion(flat.id, std::vector<VertexOcclusion>(4, VertexOcclusion{{0, 1, 0}, 0.5f}));
  flat.renderer->set_features({.antialiasing = false, .self_occlusion = true, .noise = false, .blur = false});
  std::vector<std::pair<float, float>> seen;
  for (float blocked : {0.5f, 1.0f, 0.0f}) {
    flat.renderer->set_object_lights_blocked(flat.id, std::vector<float>(4, blocked));
    seen.push_back({centre_value(), expected(up, 0.5, 1.0 - blocked)});
    std::printf("lights blocked %.1f: pixel %.4f, CPU %.4f\n", blocked, seen.back().first, seen.back().second);
    EXPECT_NEAR(seen.back().first, seen.back().second, 0.01f * seen.back().second + 0.002f);
  }
  // The sun matters here: wholly blocked is far darker than open.
  EXPECT_LT(seen[1].first, 0.5f * seen[2].first);
  // Self-occlusion off: the blocked share and the open share are ignored.
  flat.renderer->set_features(kNone);
  EXPECT_NEAR(centre_value(), expected(n, 1.0, 1.0), 0.01f * expected(n, 1.0, 1.0) + 0.002f);
  EXPECT_THROW(flat.renderer->set_object_lights_blocked(flat.id, std::vector<float>(3)), InputError);
}

TEST(CompositeFeatures, MotionBlurIsTheMeanOfTheShuttersInstants) {
  headless_context();
  FlatObject flat(0.5f, 0.5f, {0.002f, 0.0f, -2.0f});  // its edges 0.15 px off the pixels' centres
  const cv::Mat black(120, 160, CV_8UC3, cv::Scalar::all(0));
  // Four instants, the quad 8 px to the right (75 px per metre at 2 m) over the shutter.
  const double travel = 8.0 / 75.0;
  std::vector<gl::ShutterInstant> moving_object, moving_camera;
  std::vector<double> offsets;
  for (int i = 0; i < 4; ++i) {
    offsets.push_back(((i + 0.5) / 4.0 - 0.5) * travel);
    moving_object.push_back({flat.pose, {glm::translate(glm::dmat4(1.0), glm::dvec3(offsets.back(), 0, 0))}});
    // The camera moving the other way instead: the same motion in the image.
    moving_camera.push_back({look_at({-offsets.back(), 0, 0}, {-offsets.back(), 0, -1}), {glm::dmat4(1.0)}});
  }
  const auto row = [](const cv::Mat& bgr8) { return linear_of(bgr8).row(60).clone(); };
  const auto partly_covered = [](const cv::Mat& linear_row) {
    int n = 0;
    for (int c = 0; c < linear_row.cols; ++c)
      n += linear_row.at<cv::Vec3f>(0, c)[1] > 0.02f && linear_row.at<cv::Vec3f>(0, c)[1] < 0.48f;
    return n;
  };

  // Without antialiasing each instant covers whole pixels, so the blurred edge is a ramp
  // of quarters, three steps two pixels wide at each side.
  flat.renderer->set_features({.antialiasing = false, .self_occlusion = false, .noise = false, .blur = false});
  const cv::Mat sharp = flat.renderer->render_overlay(black, flat.pose, 1.0);
  const cv::Mat blurred = row(flat.renderer->render_overlay(black, flat.pose, 1.0, nullptr, moving_object));
  cv::Mat reference = cv::Mat::zeros(1, 160, CV_32FC3);
  for (const double x : offsets) {
    flat.renderer->set_object_pose(flat.id, glm::translate(glm::dmat4(1.0), glm::dvec3(x, 0, 0)));
    reference += row(flat.renderer->render_overlay(black, flat.pose, 1.0)) / 4.0;
  }
  flat.renderer->set_object_pose(flat.id, glm::dmat4(1.0));
  const double worst = cv::norm(blurred, reference, cv::NORM_INF);
  std::printf(
      "motion blur over 8 px: %d partly covered pixels (12 expected), worst |blurred - mean of instants| %.4f\n",
      partly_covered(blurred), worst);
  EXPECT_LT(worst, 0.004) << "the mean of the frames drawn at each instant";
  EXPECT_EQ(partly_covered(blurred), 12);
  EXPECT_EQ(partly_covered(row(sharp)), 0);
  EXPECT_NEAR(cv::sum(blurred)[1], cv::sum(row(sharp))[1], 0.01 * cv::sum(row(sharp))[1]) << "light is conserved";
  const cv::Mat camera_moved = row(flat.renderer->render_overlay(black, flat.pose, 1.0, nullptr, moving_camera));
  EXPECT_LT(cv::norm(camera_moved, blurred, cv::NORM_INF), 0.004) << "only the motion relative to the camera counts";
  EXPECT_EQ(cv::norm(flat.renderer->render_overlay(black, flat.pose, 1.0), sharp, cv::NORM_INF), 0.0)
      << "the poses set stay as they were";

  // Antialiased, the same light, and the ramp as before.
  flat.renderer->set_features({.antialiasing = true, .self_occlusion = false, .noise = false, .blur = false});
  const cv::Mat smooth = row(flat.renderer->render_overlay(black, flat.pose, 1.0, nullptr, moving_object));
  EXPECT_NEAR(cv::sum(smooth)[1], cv::sum(row(sharp))[1], 0.01 * cv::sum(row(sharp))[1]);
  EXPECT_GE(partly_covered(smooth), 12);

  // Switched off, or one instant: drawn once.
  flat.renderer->set_features(kNone);
  EXPECT_EQ(cv::norm(flat.renderer->render_overlay(black, flat.pose, 1.0, nullptr, moving_object), sharp, cv::NORM_INF),
            0.0);
  flat.renderer->set_features({.antialiasing = false, .self_occlusion = false, .noise = false, .blur = false});
  EXPECT_EQ(cv::norm(flat.renderer->render_overlay(black, flat.pose, 1.0, nullptr, std::span(moving_object).first(1)),
                     flat.renderer->render_overlay(black, flat.pose, 1.0), cv::NORM_INF),
            0.0);
  std::vector<gl::ShutterInstant> wrong = moving_object;
  wrong[2].T_world_model.clear();
  EXPECT_THROW(flat.renderer->render_overlay(black, flat.pose, 1.0, nullptr, wrong), InputError);
}

// Luma (JFIF's) of 8-bit BGR, in code values.
cv::Mat luma_of(const cv::Mat& bgr8) {
  cv::Mat f, y;
  bgr8.convertTo(f, CV_32FC3);
  cv::transform(f, y, cv::Matx13f(0.114f, 0.587f, 0.299f));
  return y;
}

TEST(CompositeFeatures, ChromaIsSubsampledAsTheCamerasCodecDoes) {
  headless_context();
  // A red quad on a green video, its edges on pixel boundaries (x 40|41 and 118|119), each
  // 2×2 chroma block at its left edge half red, half green.
  FlatObject flat(0.5f, 0.52f);
  flat.renderer->set_object_material(flat.id, glm::vec3(1.0f, 0.12f, 0.08f), uniform_sh(0.5f));
  const cv::Mat video(120, 160, CV_8UC3, cv::Scalar(50, 150, 60));
  flat.renderer->set_features({.antialiasing = false, .self_occlusion = false, .noise = false, .blur = false});
  const cv::Mat plain = flat.renderer->render_overlay(video, flat.pose, 1.0);
  gl::VideoRadiometry radiometry;
  radiometry.chroma_horizontal = radiometry.chroma_vertical = 2;
  flat.renderer->set_video_radiometry(radiometry);
  const cv::Mat subsampled = flat.renderer->render_overlay(video, flat.pose, 1.0);

  // The reference: libjpeg itself (OpenCV's JPEG codec, 4:2:0, quality 100) on the plain composite.
  std::vector<std::uint8_t> bytes;
  cv::imencode(".jpg", plain, bytes, {cv::IMWRITE_JPEG_QUALITY, 100});
  ASSERT_EQ(capture::chroma_sampling_of_jpeg(bytes), (capture::ChromaSampling{2, 2}));
  const cv::Mat jpeg = cv::imdecode(bytes, cv::IMREAD_COLOR);
  const cv::Mat mask = flat.renderer->render_object_mask(flat.pose);
  cv::Mat near;  // within 3 px of the quad's outline, where chroma mixes
  cv::dilate(mask, near, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(7, 7)));
  cv::Mat inner;
  cv::erode(mask, inner, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(7, 7)));
  near &= ~inner;
  double worst = 0, worst_plain = 0;
  for (int r = 0; r < 120; ++r)
    for (int c = 0; c < 160; ++c) {
      if (!near.at<std::uint8_t>(r, c)) continue;
      for (int k = 0; k < 3; ++k) {
        const double j = jpeg.at<cv::Vec3b>(r, c)[k];
        worst = std::max(worst, std::abs(subsampled.at<cv::Vec3b>(r, c)[k] - j));
        worst_plain = std::max(worst_plain, std::abs(plain.at<cv::Vec3b>(r, c)[k] - j));
      }
    }
  std::printf("chroma 4:2:0 at the outline: worst |composite - libjpeg| %.0f levels, without it %.0f\n", worst,
              worst_plain);
  EXPECT_LE(worst, 4.0) << "the codec's chroma, within its own rounding";
  EXPECT_GT(worst_plain, 40.0) << "the plain composite's outline is far from the codec's";
  // Each pixel keeps its own luma; far from the quad the video is untouched.
  EXPECT_LT(cv::norm(luma_of(subsampled), luma_of(plain), cv::NORM_INF), 1.01);
  cv::Mat far;
  cv::dilate(mask, far, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(9, 9)));
  EXPECT_EQ(cv::norm(subsampled, plain, cv::NORM_INF, ~far), 0.0);
  EXPECT_EQ(cv::norm(subsampled, video, cv::NORM_INF, ~far), 0.0);

  // 4:2:2 (YUYV) mixes along rows only: the row above the quad keeps the video's colour.
  radiometry.chroma_vertical = 1;
  flat.renderer->set_video_radiometry(radiometry);
  const cv::Mat rows_only = flat.renderer->render_overlay(video, flat.pose, 1.0);
  const cv::Rect above(60, 20, 40, 1);  // the quad's top edge lies between rows 20 and 21
  ASSERT_EQ(cv::countNonZero(mask(above + cv::Point(0, 1))), 40);
  EXPECT_EQ(cv::norm(rows_only(above), video(above), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(subsampled(above), video(above), cv::NORM_INF), 20.0);
  EXPECT_GT(cv::norm(rows_only.row(60).colRange(38, 42), plain.row(60).colRange(38, 42), cv::NORM_INF), 20.0);

  // Switched off: the plain composite.
  flat.renderer->set_features(
      {.antialiasing = false, .self_occlusion = false, .noise = false, .blur = false, .chroma = false});
  EXPECT_EQ(cv::norm(flat.renderer->render_overlay(video, flat.pose, 1.0), plain, cv::NORM_INF), 0.0);
  radiometry.chroma_horizontal = 3;
  EXPECT_THROW(flat.renderer->set_video_radiometry(radiometry), InputError);
}

}  // namespace
}  // namespace lumar::test
