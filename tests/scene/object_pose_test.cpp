// Object poses in a manifest: the three forms of rotation agree with each other,
// "bottom-centre" puts the bottom of the rotated model's box at the translation, and
// "on_floor" rests the lowest point on the proxy surface below (the table top, not the
// floor, when the object stands over the table). An animated object's "path": its keys
// reached at their times, straight lines and slerp between them, resting on the floor
// all the way.
#include <gtest/gtest.h>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <cmath>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <sstream>

#include "lumar/base/error.h"
#include "lumar/scene/loaded_scene.h"
#include "test_paths.h"

namespace lumar {
namespace {

class ObjectPose : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::scratch_dir("object-pose"); }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  // The sample room's manifest with its figurine's "pose" replaced, and a "path" if given.
  std::filesystem::path manifest(const std::string& pose_json, const std::string& path_json = "") {
    const auto src = test::source_dir() / "data/scenes/room";
    const auto path = dir_ / "scene.json";
    std::ofstream(path) << R"({"format": "lumar-scene", "version": 1,
      "room": {"mesh": ")"
                        << (src / "room.obj").string() << R"("},
      "environment_map": {"path": ")"
                        << (test::source_dir() / "data/envmaps/interior.exr").string()
                        << R"(", "capture_position": [0, 1.4, 0]},
      "movement_box": {"min": [-1.2, 0.0, -0.4], "max": [0.4, 1.0, 1.2]},
      "objects": [{"name": "figurine", "mesh": ")"
                        << (test::source_dir() / "data/models/parasaurolophus_6700.ply").string() << R"(",
                   "pose": )"
                        << pose_json << (path_json.empty() ? "" : ", \"path\": " + path_json) << "}]}";
    return path;
  }

  std::pair<glm::dvec3, glm::dvec3> posed_bounds(const LoadedScene& s) {
    const auto [lo, hi] = transformed(s.objects[0].model, s.objects[0].T_world_model).bounds();
    return {glm::dvec3(lo), glm::dvec3(hi)};
  }

  std::filesystem::path dir_;
};

TEST_F(ObjectPose, TheThreeRotationFormsAgree) {
  const Scene axis = load_scene(manifest(R"({"rotation_axis": [0, 1, 0], "rotation_deg": 30})"));
  const Scene ypr = load_scene(manifest(R"({"yaw_pitch_roll_deg": [30, 0, 0]})"));
  const double h = glm::radians(15.0);  // a 30 degree turn about +Y
  const Scene quat = load_scene(manifest("{\"rotation_wxyz\": [" + std::to_string(std::cos(h)) + ", 0, " +
                                         std::to_string(std::sin(h)) + ", 0]}"));
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      EXPECT_NEAR(axis.objects[0].T_world_model[c][r], ypr.objects[0].T_world_model[c][r], 1e-9);
      EXPECT_NEAR(axis.objects[0].T_world_model[c][r], quat.objects[0].T_world_model[c][r], 1e-6);
    }
  // Yaw, then pitch, then roll: R = Ry Rx Rz. A pitch of 90 turns the model's +Z to -Y.
  const Scene pitched = load_scene(manifest(R"({"yaw_pitch_roll_deg": [0, 90, 0]})"));
  const glm::dvec3 z = glm::dmat3(pitched.objects[0].T_world_model) * glm::dvec3(0, 0, 1);
  EXPECT_NEAR(glm::distance(z, glm::dvec3(0, -1, 0)), 0.0, 1e-12);
}

TEST_F(ObjectPose, OneRotationFormOnlyAndUnitQuaternions) {
  EXPECT_THROW(load_scene(manifest(R"({"rotation_deg": 30, "yaw_pitch_roll_deg": [30, 0, 0]})")), InputError);
  EXPECT_THROW(load_scene(manifest(R"({"rotation_wxyz": [1, 1, 0, 0]})")), InputError);
  EXPECT_THROW(load_scene(manifest(R"({"model_origin": "top"})")), InputError);
  EXPECT_THROW(load_scene(manifest(R"({"on_floor": "yes"})")), InputError);
}

TEST_F(ObjectPose, BottomCentreLandsAtTheTranslation) {
  const LoadedScene s = load_scene_files(manifest(
      R"({"translation": [-0.3, 0.2, 0.5], "yaw_pitch_roll_deg": [40, -90, 0], "scale": 0.002, "model_origin": "bottom-centre"})"));
  const auto [lo, hi] = posed_bounds(s);
  EXPECT_NEAR(0.5 * (lo.x + hi.x), -0.3, 1e-6);
  EXPECT_NEAR(lo.y, 0.2, 1e-6);
  EXPECT_NEAR(0.5 * (lo.z + hi.z), 0.5, 1e-6);
}

TEST_F(ObjectPose, OnFloorRestsOnTheSurfaceBelow) {
  // Over the open floor: the lowest point comes down to y = 0.
  const LoadedScene floor = load_scene_files(manifest(
      R"({"translation": [0, 0.4, 0.5], "yaw_pitch_roll_deg": [0, -90, 0], "scale": 0.002, "model_origin": "bottom-centre", "on_floor": true})"));
  EXPECT_NEAR(posed_bounds(floor).first.y, 0.0, 1e-6);
  // Below the floor, it comes up to it just the same.
  const LoadedScene sunk = load_scene_files(manifest(
      R"({"translation": [0, -0.05, 0.5], "yaw_pitch_roll_deg": [0, -90, 0], "scale": 0.002, "model_origin": "bottom-centre", "on_floor": true})"));
  EXPECT_NEAR(posed_bounds(sunk).first.y, 0.0, 1e-6);
  // Over the sample room's table (a box up to y = 0.72 around x = 0.9, z = -0.7), on its top.
  const auto [room_lo, room_hi] = floor.room.bounds();
  double table_top = 0;
  for (const glm::vec3& p : floor.room.positions)
    if (p.y > 0.01f && p.y < room_hi.y - 0.01f) table_top = std::max(table_top, double(p.y));
  ASSERT_GT(table_top, 0.3);
  const LoadedScene table = load_scene_files(manifest(
      R"({"translation": [0.85, 1.5, -0.7], "yaw_pitch_roll_deg": [0, -90, 0], "scale": 0.001, "model_origin": "bottom-centre", "on_floor": true})"));
  EXPECT_NEAR(posed_bounds(table).first.y, table_top, 1e-6);
}

TEST_F(ObjectPose, StandingOutsideTheMovementBoxOrTheRoomIsWarned) {
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  spdlog::default_logger()->sinks().push_back(sink);
  const auto warnings = [&](const std::string& pose) {
    log.str("");
    load_scene_files(manifest(pose));
    return log.str();
  };
  // Inside both: silent.
  const std::string inside = warnings(
      R"({"translation": [-0.3, 0, 0.5], "yaw_pitch_roll_deg": [0, 0, 90], "scale": 0.002, "model_origin": "bottom-centre"})");
  // Inside the room, beyond the movement box (x <= 0.4): the lighting is extrapolated.
  const std::string beyond_box = warnings(
      R"({"translation": [1.0, 0, 0.5], "yaw_pitch_roll_deg": [0, 0, 90], "scale": 0.002, "model_origin": "bottom-centre"})");
  // Far outside the room too.
  const std::string outside = warnings(
      R"({"translation": [20, 0, 0.5], "yaw_pitch_roll_deg": [0, 0, 90], "scale": 0.002, "model_origin": "bottom-centre"})");
  spdlog::default_logger()->sinks().pop_back();
  EXPECT_EQ(inside, "");
  EXPECT_NE(beyond_box.find("objects[0] (figurine): stands outside the movement box"), std::string::npos) << beyond_box;
  EXPECT_EQ(beyond_box.find("outside the proxy room"), std::string::npos) << beyond_box;
  EXPECT_NE(outside.find("stands outside the movement box"), std::string::npos) << outside;
  EXPECT_NE(outside.find("reaches outside the proxy room"), std::string::npos) << outside;
}

// The courtyard's proxy is a ground plane: open upwards, so objects standing on it are
// inside it, and the scene loads without a warning.
TEST_F(ObjectPose, AGroundPlaneBoundsNothingAlongItsNormal) {
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  spdlog::default_logger()->sinks().push_back(sink);
  const LoadedScene courtyard = load_scene_files(test::source_dir() / "data/scenes/courtyard/scene.json");
  spdlog::default_logger()->sinks().pop_back();
  EXPECT_EQ(log.str(), "");
  ASSERT_EQ(courtyard.objects.size(), 2u);
  EXPECT_TRUE(courtyard.distant());
  EXPECT_NEAR(courtyard.room.bounds().second.y - courtyard.room.bounds().first.y, 0.0, 1e-9);
  // The sphere rests on the ground.
  glm::dvec3 lo(1e9);
  for (const glm::vec3& p : courtyard.objects[1].model.positions)
    lo = glm::min(lo, glm::dvec3(courtyard.objects[1].T_world_model * glm::dvec4(glm::dvec3(p), 1.0)));
  EXPECT_NEAR(lo.y, 0.0, 1e-6);
}

constexpr const char* kWalkPose =
    R"({"yaw_pitch_roll_deg": [20, 0, 90], "scale": 0.002, "model_origin": "bottom-centre", "on_floor": true})";
constexpr const char* kWalkPath = R"([{"t": 0.5, "translation": [-0.8, 0.3, 0.6]},
      {"t": 1.5, "translation": [-0.2, 0.0, 0.2], "rotation_axis": [0, 1, 0], "rotation_deg": 80}])";

glm::dquat rotation_of(const glm::dmat4& T) {
  const glm::dmat3 M(T);
  return glm::normalize(glm::quat_cast(M / glm::length(M[0])));
}

TEST_F(ObjectPose, PathKeysAreReachedAtTheirTimesAndHeldBeyond) {
  const LoadedScene s = load_scene_files(manifest(kWalkPose, kWalkPath));
  const LoadedObject& o = s.objects[0];
  ASSERT_EQ(o.path.keys().size(), 2u);
  EXPECT_EQ(o.T_world_model, o.path.keys()[0].T_world_model);  // the still pose is the path's start
  for (double t : {0.0, 0.5, 1.5, 9.0}) {
    const LoadedObject at = [&] {
      LoadedObject c = o;
      c.T_world_model = o.pose_at(t);
      return c;
    }();
    const auto [lo, hi] = transformed(at.model, at.T_world_model).bounds();
    const glm::dvec3 want = t < 1.0 ? glm::dvec3(-0.8, 0.0, 0.6) : glm::dvec3(-0.2, 0.0, 0.2);
    // Bottom-centre lands at the key's translation, brought down onto the floor.
    EXPECT_NEAR(0.5 * (lo.x + hi.x), want.x, 1e-6) << t;
    EXPECT_NEAR(lo.y, 0.0, 1e-6) << t;
    EXPECT_NEAR(0.5 * (lo.z + hi.z), want.z, 1e-6) << t;
  }
  // The key's turn comes on top of the pose's rotation: R = Ry(80°) R_pose.
  const glm::dquat turn = rotation_of(o.pose_at(1.5)) * glm::inverse(rotation_of(o.pose_at(0.5)));
  EXPECT_NEAR(glm::degrees(glm::angle(turn)), 80.0, 1e-6);
  EXPECT_NEAR(std::abs(glm::axis(turn).y), 1.0, 1e-9);
  // Without a path: the pose at every time.
  const LoadedScene still = load_scene_files(manifest(kWalkPose));
  EXPECT_TRUE(still.objects[0].path.empty());
  EXPECT_EQ(still.objects[0].pose_at(3.0), still.objects[0].T_world_model);
}

TEST_F(ObjectPose, BetweenKeysTheCentreMovesStraightAndTheTurnIsShared) {
  const LoadedScene s = load_scene_files(manifest(kWalkPose, kWalkPath));
  const LoadedObject& o = s.objects[0];
  const auto [mlo, mhi] = o.model.bounds();
  const glm::dvec4 centre(0.5 * (glm::dvec3(mlo) + glm::dvec3(mhi)), 1.0);
  const glm::dvec3 a(o.pose_at(0.5) * centre), b(o.pose_at(1.5) * centre);
  const glm::dquat ra = rotation_of(o.pose_at(0.5));
  for (double u : {0.1, 0.25, 0.5, 0.9}) {
    const glm::dmat4 T = o.pose_at(0.5 + u);
    EXPECT_NEAR(glm::distance(glm::dvec3(T * centre), glm::mix(a, b, u)), 0.0, 1e-9) << u;
    EXPECT_NEAR(glm::degrees(glm::angle(rotation_of(T) * glm::inverse(ra))), 80.0 * u, 1e-6) << u;
    EXPECT_NEAR(glm::length(glm::dmat3(T)[0]), 0.002, 1e-12);
    // Turning about the vertical keeps the lowest point on the floor between the keys.
    EXPECT_NEAR(transformed(o.model, T).bounds().first.y, 0.0, 1e-6) << u;
  }
}

TEST_F(ObjectPose, BadPathsAreRefusedNamingTheKey) {
  const auto error = [&](const std::string& path) {
    try {
      load_scene(manifest(kWalkPose, path));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error(R"([{"t": 0, "translation": [0, 0, 0]}])").find("objects[0].path: expected an array of at least 2"),
            std::string::npos);
  EXPECT_NE(error(R"([{"t": 1, "translation": [0, 0, 0]}, {"t": 1, "translation": [0, 0, 0]}])")
                .find("objects[0].path[1].t: must be later than the key before"),
            std::string::npos);
  EXPECT_NE(error(R"([{"t": 0}, {"t": 1, "translation": [0, 0, 0]}])").find("path[0].translation: missing"),
            std::string::npos);
  EXPECT_NE(error(R"([{"t": 0, "translation": [0, 0, 0], "scale": 2}, {"t": 1, "translation": [0, 0, 0]}])")
                .find("path[0].scale: unknown key"),
            std::string::npos);
  EXPECT_NE(error(R"([{"t": -1, "translation": [0, 0, 0]}, {"t": 1, "translation": [0, 0, 0]}])")
                .find("path[0].t: expected seconds"),
            std::string::npos);
  EXPECT_NE(error(R"([{"t": 0, "translation": [0, 0, 0]}, {"t": 1, "translation": [0, 0, 1e9]}])")
                .find("path[1].translation: expected coordinates"),
            std::string::npos);
  // Off the room: on_floor finds no surface below that key.
  EXPECT_THROW(load_scene_files(manifest(kWalkPose, R"([{"t": 0, "translation": [0, 0, 0]},
      {"t": 1, "translation": [50, 0, 0]}])")),
               InputError);
}

}  // namespace
}  // namespace lumar
