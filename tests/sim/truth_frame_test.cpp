// The truth frame (lumar/sim/truth_frame.h) against a case solved on paper: a closed box
// room of uniform radiance 1, a sphere of albedo ½ resting on its floor, a pinhole camera
// straight above it. The sphere sees radiance 1 everywhere, so it sends ½; its outline is
// a circle of radius f·R/√(D² − R²) pixels; and the floor at distance d from the sphere's
// centre keeps 1 − (1 − ½)(R/d)³ of its light (what the sphere blocks, less what it
// reflects back).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lumar/base/constants.h"
#include "lumar/calib/camera_file.h"
#include "lumar/capture/recording_reader.h"
#include "lumar/lighting/composite_reference.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/sim/synthetic_recording.h"
#include "lumar/sim/truth_frame.h"
#include "test_geometry.h"
#include "test_paths.h"

namespace lumar::test {
namespace {

constexpr double kRadius = 0.5, kHeight = 4.0;

// A closed room of uniform radiance, or (`distant`) a uniform distant sky over a ground
// plane: the sphere's light and the floor's ratio are the same on paper.
struct UniformRoomWithSphere {
  EnvironmentMap map;
  std::unique_ptr<RoomRadiance> room;
  RayScene ground;  // the distant sky's: the surface its map is shown on
  const RayScene* surfaces = nullptr;
  std::vector<LoadedObject> objects;
  explicit UniformRoomWithSphere(bool distant = false) {
    map.width = 128, map.height = 64;
    map.rgb.assign(std::size_t(map.width) * map.height * 3, 1.0f);
    map.capture_position = {0.0, 2.5, 0.0};
    if (distant) {
      room = std::make_unique<RoomRadiance>(map, RadianceSettings{});
      ground.add_static(make_quad({0, 0, 0}, {50, 0, 0}, {0, 0, 50}, {0, 1, 0}));
      ground.commit();
      surfaces = &ground;
    } else {
      room = std::make_unique<RoomRadiance>(map, make_box({-3, 0, -3}, {3, 5, 3}, true), RadianceSettings{});
      surfaces = room->ray_scene();
    }
    LoadedObject sphere;
    sphere.model = make_sphere(glm::vec3(0.0f), float(kRadius), 96, 48);
    sphere.T_world_model = glm::translate(glm::dmat4(1.0), glm::dvec3(0, kRadius, 0));
    sphere.albedo = glm::vec3(0.5f);
    objects.push_back(sphere);
  }
};

CameraIntrinsics looking_down_camera() {
  CameraIntrinsics c;
  c.width = 160, c.height = 120;
  c.fx = c.fy = 100.0;
  c.cx = 80.0, c.cy = 60.0;
  return c;
}

// Straight down from kHeight: camera x = world +X, camera y (down the image) = world +Z.
Pose looking_down_pose() {
  Pose p;
  p.rotation = glm::quat_cast(glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0)));
  p.translation = {0.0, kHeight, 0.0};
  return p;
}

void check_against_paper(int ratio_stride, bool distant = false) {
  UniformRoomWithSphere scene(distant);
  CompositeReferenceSettings rs;
  rs.cone_strata = 16;
  const CompositeReference reference(*scene.room, scene.objects, rs);
  const CameraIntrinsics camera = looking_down_camera();
  const Pose pose = looking_down_pose();
  sim::TruthSettings ts;
  ts.ratio_stride = ratio_stride;
  const cv::Mat empty(camera.height, camera.width, CV_32FC3, cv::Scalar::all(1.0));
  const sim::TruthFrame truth = sim::render_truth_frame(reference, *scene.surfaces, camera, pose, empty, ts);

  // The outline: the sphere's centre is D = kHeight − R below the camera, on its axis.
  const double D = kHeight - kRadius;
  const double outline = camera.fx * kRadius / std::sqrt(D * D - kRadius * kRadius);
  const double covered = cv::sum(truth.coverage)[0];
  EXPECT_NEAR(covered, kPi * outline * outline, 0.02 * kPi * outline * outline);

  double worst_object = 0, worst_floor = 0;
  for (int r = 0; r < camera.height; ++r)
    for (int c = 0; c < camera.width; ++c) {
      const cv::Vec3f L = truth.radiance.at<cv::Vec3f>(r, c);
      if (truth.coverage.at<float>(r, c) > 0) {
        worst_object = std::max(worst_object, double(std::abs(L[1] - 0.5f)));
        continue;
      }
      // The floor point this pixel sees (the outermost columns see the walls instead, a
      // metre further from the sphere: there it changes the light by less than 0.2 %).
      const double x = (c - camera.cx) / camera.fx * kHeight, z = (r - camera.cy) / camera.fy * kHeight;
      const double d = std::sqrt(x * x + z * z + kRadius * kRadius);
      const double expected = 1.0 - 0.5 * std::pow(kRadius / d, 3);
      worst_floor = std::max(worst_floor, std::abs(L[1] - expected));
    }
  std::printf("%s, stride %d: %.0f pixels covered (paper %.0f); worst error on the sphere %.4f, on the floor %.4f\n",
              distant ? "distant sky over a ground plane" : "closed room", ratio_stride, covered,
              kPi * outline * outline, worst_object, worst_floor);
  EXPECT_LT(worst_object, 0.02);
  EXPECT_LT(worst_floor, 0.03);
}

TEST(TruthFrame, SphereInAUniformRoomMatchesPaperAtEveryPixel) { check_against_paper(1); }

TEST(TruthFrame, InterpolatedRatioStaysCloseToPaper) { check_against_paper(3); }

// Under a distant map the objects' shadows fall on the room's mesh the map is shown on,
// which the map's RoomRadiance does not hold (the courtyard's truth once had no shadows).
TEST(TruthFrame, UnderADistantSkyTheShadowFallsOnTheGround) { check_against_paper(1, true); }

TEST(TruthFrame, FarFromTheObjectTheEmptyRoomIsKeptExactly) {
  // Out of every object's reach the room's pixels are the empty room's, bit for bit.
  UniformRoomWithSphere scene;
  CompositeReferenceSettings rs;
  rs.reach = 2.0;  // 2 × the bounding radius (0.87 m): the image's corners are beyond
  const CompositeReference reference(*scene.room, scene.objects, rs);
  const CameraIntrinsics camera = looking_down_camera();
  cv::Mat empty(camera.height, camera.width, CV_32FC3);
  cv::randu(empty, 0.2, 3.0);
  const sim::TruthFrame truth = sim::render_truth_frame(reference, *scene.surfaces, camera, looking_down_pose(), empty);
  const cv::Rect corner(0, 0, 20, 20);
  EXPECT_EQ(cv::norm(truth.radiance(corner), empty(corner), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(truth.radiance, empty, cv::NORM_INF), 0.1);  // the sphere and its shadow
}

// Mean |a − b| / mean b over the pixels b covers (green channel).
double mean_relative_difference(const sim::TruthFrame& a, const sim::TruthFrame& b, int* pixels = nullptr) {
  double difference = 0, total = 0;
  int n = 0;
  for (int r = 0; r < b.coverage.rows; ++r)
    for (int c = 0; c < b.coverage.cols; ++c) {
      if (b.coverage.at<float>(r, c) == 0) continue;
      difference += std::abs(a.radiance.at<cv::Vec3f>(r, c)[1] - b.radiance.at<cv::Vec3f>(r, c)[1]);
      total += b.radiance.at<cv::Vec3f>(r, c)[1];
      ++n;
    }
  if (pixels) *pixels = n;
  return difference / total;
}

TEST(TruthFrame, PerPixelObjectsConvergeAndVertexShadingIsCoarser) {
  // The figurine as synth's orbit ends. Object pixels integrate their own E (16² rays):
  // against 32² rays they differ by the rays' noise only, which the measure's 5×5 box
  // averages. E per vertex, interpolated, is systematically off by more (the knob's cost).
  const LoadedScene scene = load_scene_files(source_dir() / "data/scenes/room/scene.json");
  const auto room = scene_radiance(scene, truth_radiance_settings());
  const CompositeReference reference(*room, scene.objects);
  CompositeReferenceSettings fine_settings;
  fine_settings.object_strata = 32;
  const CompositeReference fine_reference(*room, scene.objects, fine_settings);
  const CameraIntrinsics camera = calib::load_camera_file(source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  const auto [lo, hi] = transformed(scene.objects[0].model, scene.objects[0].T_world_model).bounds();
  const Pose pose = sim::orbit_camera_pose({0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z)}, 1.0, 60.0);
  const cv::Mat empty = cv::Mat::zeros(camera.height, camera.width, CV_32FC3);
  sim::TruthSettings per_vertex;
  per_vertex.per_pixel_objects = false;
  const sim::TruthFrame fine = sim::render_truth_frame(fine_reference, *room->ray_scene(), camera, pose, empty);
  const sim::TruthFrame pixel = sim::render_truth_frame(reference, *room->ray_scene(), camera, pose, empty);
  const sim::TruthFrame vertex =
      sim::render_truth_frame(reference, *room->ray_scene(), camera, pose, empty, per_vertex);
  int pixels = 0;
  const double noise = mean_relative_difference(pixel, fine, &pixels), coarse = mean_relative_difference(vertex, fine);
  std::printf("%d figurine pixels against 32^2 rays per pixel: 16^2 per pixel %.2f %%, per vertex %.2f %%\n", pixels,
              100 * noise, 100 * coarse);
  EXPECT_GT(pixels, 2000);
  EXPECT_LT(noise, 0.03);
  EXPECT_GT(coarse, noise);
  // Specks: figurine pixels below a quarter of the median of their 3×3 neighbours. The
  // scan had holes (crest, arm, toes) through which rays saw the inside of its shell, dark
  // and lit from the other side: 37 such pixels here. The scenes' figurine is now closed
  // (docs/solid.md): none. (Rays that slip through cracks are the sphere tests' concern.)
  int specks = 0;
  for (int r = 1; r + 1 < camera.height; ++r)
    for (int c = 1; c + 1 < camera.width; ++c) {
      if (pixel.coverage.at<float>(r, c) == 0) continue;
      std::vector<float> around;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc)
          if ((dr || dc) && pixel.coverage.at<float>(r + dr, c + dc) > 0)
            around.push_back(pixel.radiance.at<cv::Vec3f>(r + dr, c + dc)[1]);
      if (around.size() < 4) continue;
      std::nth_element(around.begin(), around.begin() + around.size() / 2, around.end());
      if (pixel.radiance.at<cv::Vec3f>(r, c)[1] < 0.25f * around[around.size() / 2]) ++specks;
    }
  EXPECT_EQ(specks, 0);
}

TEST(TruthFrame, SynthWritesTheVideoWithTheObjectsInItAndItsNoiseFloor) {
  // The sample room with its figurine, two lossless frames: where the figurine changes
  // nothing the truth is the video's frame bit for bit (the same noise), around it the
  // floor is darker, the mask covers the figurine, and the other seed differs by noise only.
  const Scratch scratch("truth-synth");
  sim::SynthSettings s;
  s.scene = source_dir() / "data/scenes/room/scene.json";
  s.out = scratch.dir / "rec";
  s.camera = calib::load_camera_file(source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  s.frames = 2;
  s.supersample = 1;
  s.codec = "ffv1";
  s.truth = true;
  sim::synthesize_recording(s);
  const capture::RecordingReader reader(s.out);
  auto frames = reader.open_frames();
  capture::Frame frame;
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(frames->read(frame));
    const auto file = [&](const char* kind) {
      return (s.out / "truth" / fmt::format("{}-{:05d}.png", kind, k)).string();
    };
    const cv::Mat truth = cv::imread(file("frame")), other = cv::imread(file("other-seed")),
                  mask = cv::imread(file("mask"), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(truth.empty() || other.empty() || mask.empty());
    const int covered = cv::countNonZero(mask);
    cv::Mat differs;
    cv::absdiff(truth, frame.image, differs);
    cv::cvtColor(differs, differs, cv::COLOR_BGR2GRAY);
    const int changed = cv::countNonZero(differs), total = int(differs.total());
    // Dark where the figurine shades the floor: the truth's mean below the video's there.
    cv::Mat shadow = (differs > 0) & (mask == 0);
    const double darker = cv::mean(frame.image, shadow)[1] - cv::mean(truth, shadow)[1];
    const double noise = cv::norm(truth, other, cv::NORM_L2) / std::sqrt(double(truth.total() * 3));
    std::printf(
        "frame %d: figurine %d pixels; %d of %d pixels changed; shadow %.1f levels darker; "
        "other seed RMS %.2f levels\n",
        k, covered, changed, total, darker, noise);
    EXPECT_GT(covered, 2000);
    EXPECT_LT(changed, total / 2);  // most of the room is out of the figurine's reach
    EXPECT_GT(darker, 0.5);
    // √2 × the sensor's noise (about 3.5 levels per channel at these exposures).
    EXPECT_GT(noise, 2.0);
    EXPECT_LT(noise, 8.0);
  }
}

// --room-differs --truth: the truth is rendered in the room the video shows (a table, a box,
// a cabinet, a wall 3 cm off with a recess), not in the proxy the overlay is given. The
// figurine's shadow and the light it reflects fall on the box beside it, so the truth's
// ratio to the empty room differs from the plain room's there; computed on the proxy (as
// before this test) the two ratios would be the same at every pixel.
TEST(TruthFrame, TheTruthOfARoomUnlikeTheProxyIsRenderedInThatRoom) {
  const Scratch scratch("truth-room-differs");
  cv::Mat ratio[2], mask;
  for (int differs : {0, 1}) {
    sim::SynthSettings s;
    s.scene = source_dir() / "data/scenes/room/scene.json";
    s.out = scratch.dir / (differs ? "differs" : "plain");
    s.camera = calib::load_camera_file(source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
    s.frames = 2;
    s.supersample = 1;
    s.codec = "ffv1";
    s.exposure = 0.7;
    s.truth = true;
    s.room_differs = differs == 1;
    sim::synthesize_recording(s);
    cv::Mat truth = cv::imread((s.out / "truth/frame-00000.png").string(), cv::IMREAD_GRAYSCALE),
            empty = cv::imread((s.out / "truth/empty-00000.png").string(), cv::IMREAD_GRAYSCALE);
    mask = cv::imread((s.out / "truth/mask-00000.png").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(truth.empty() || empty.empty() || mask.empty());
    truth.convertTo(truth, CV_32F);
    empty.convertTo(empty, CV_32F);
    cv::blur(truth, truth, {5, 5});
    cv::blur(empty, empty, {5, 5});
    ratio[differs] = truth / cv::max(empty, 1.0f);
  }
  cv::Mat room;
  cv::dilate(mask, room, cv::Mat(), cv::Point(-1, -1), 4);
  room = room == 0;
  cv::Mat apart;
  cv::absdiff(ratio[0], ratio[1], apart);
  const int differ = cv::countNonZero((apart > 0.03) & room);
  std::printf("room pixels whose truth/empty ratio differs by over 0.03 between the two rooms: %d\n", differ);
  EXPECT_GT(differ, 50);
}

}  // namespace
}  // namespace lumar::test
