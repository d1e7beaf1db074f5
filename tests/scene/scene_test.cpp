// Scene manifests: a full valid manifest, defaults, and every error naming the file and key.
#include "lumar/scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "lumar/base/error.h"
#include "test_paths.h"

namespace lumar {
namespace {

class SceneManifest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir("scene");
    // The loader only needs the referenced files to exist; their contents are not read.
    std::ofstream(dir_ / "room.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::filesystem::create_directories(dir_ / "maps");
    std::ofstream(dir_ / "maps/interior.exr") << "placeholder";
    std::ofstream(dir_ / "figurine.ply") << "placeholder";
  }

  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  std::filesystem::path write(const std::string& json) {
    const auto path = dir_ / "scene.json";
    std::ofstream(path, std::ios::binary) << json;
    return path;
  }

  // Builds a manifest from the valid one with `from` replaced by `to`.
  std::filesystem::path write_changed(const std::string& from, const std::string& to) {
    std::string text = kValid;
    const auto p = text.find(from);
    EXPECT_NE(p, std::string::npos) << from;
    text.replace(p, from.size(), to);
    return write(text);
  }

  void expect_error(const std::filesystem::path& manifest, const std::string& key, const std::string& more = "") {
    try {
      load_scene(manifest);
      FAIL() << "no InputError; expected one about " << key;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(manifest.string() + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(key), std::string::npos) << what;
      EXPECT_NE(what.find(more), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_EQ(what.find("[json.exception"), std::string::npos) << what;  // words, not the library's codes
    }
  }

  static constexpr const char* kValid = R"({
  "format": "lumar-scene", "version": 1,
  "room": {"mesh": "room.obj", "scale": 0.01},
  "environment_map": {"path": "maps/interior.exr", "capture_position": [0, 1.2, 0], "azimuth_offset_deg": 15,
                      "distant": false},
  "movement_box": {"min": [-1, 0, -1], "max": [1, 1, 1]},
  "objects": [{"name": "figurine", "mesh": "figurine.ply", "albedo": [0.8, 0.7, 0.6],
               "pose": {"translation": [0.5, 0.25, -0.75], "rotation_axis": [0, 2, 0], "rotation_deg": 30,
                        "scale": 0.001, "model_origin": [60, -60, -634]}},
              {"name": "plain", "mesh": "figurine.ply", "bounce": false}],
  "lighting": {"method": "sh9", "irradiance": {"spacing": 0.25, "rays_per_probe": 256, "refine": false}}
})";

  std::filesystem::path dir_;
};

TEST_F(SceneManifest, ValidManifestParses) {
  const Scene scene = load_scene(write(kValid));
  EXPECT_EQ(scene.room_mesh, dir_ / "room.obj");
  EXPECT_DOUBLE_EQ(scene.room_scale, 0.01);
  EXPECT_EQ(scene.environment_map, dir_ / "maps/interior.exr");
  EXPECT_EQ(scene.capture_position, glm::dvec3(0, 1.2, 0));
  EXPECT_DOUBLE_EQ(scene.azimuth_offset_deg, 15.0);
  EXPECT_FALSE(scene.distant_map);
  EXPECT_EQ(scene.movement_min, glm::dvec3(-1, 0, -1));
  EXPECT_EQ(scene.movement_max, glm::dvec3(1, 1, 1));
  EXPECT_EQ(scene.lighting.method, "sh9");
  EXPECT_EQ(scene.lighting.spacing, 0.25);
  EXPECT_EQ(scene.lighting.rays_per_probe, 256);
  EXPECT_EQ(scene.lighting.refine, false);
  EXPECT_FALSE(scene.lighting.visibility.has_value());  // not given: the method's default
  EXPECT_FALSE(scene.lighting.max_lights.has_value());
  ASSERT_EQ(scene.objects.size(), 2u);

  const SceneObject& fig = scene.objects[0];
  EXPECT_EQ(fig.name, "figurine");
  EXPECT_EQ(fig.mesh, dir_ / "figurine.ply");
  EXPECT_EQ(fig.albedo, glm::vec3(0.8f, 0.7f, 0.6f));
  EXPECT_TRUE(fig.bounce);  // the default
  const glm::dvec3 origin(60, -60, -634), translation(0.5, 0.25, -0.75);
  const auto apply = [&](const glm::dvec3& p) { return glm::dvec3(fig.T_world_model * glm::dvec4(p, 1.0)); };
  EXPECT_NEAR(glm::distance(apply(origin), translation), 0.0, 1e-12) << "model_origin lands at translation";
  // One model unit (mm) along model +Z becomes 1 mm along Ry(30) +Z = (sin 30, 0, cos 30).
  const glm::dvec3 step = apply(origin + glm::dvec3(0, 0, 1)) - translation;
  EXPECT_NEAR(glm::distance(step, 0.001 * glm::dvec3(0.5, 0, std::sqrt(3.0) / 2)), 0.0, 1e-12);
  const glm::dvec3 up = apply(origin + glm::dvec3(0, 1, 0)) - translation;
  EXPECT_NEAR(glm::distance(up, glm::dvec3(0, 0.001, 0)), 0.0, 1e-12) << "axis (0, 2, 0) is normalised";

  const SceneObject& plain = scene.objects[1];
  EXPECT_EQ(plain.albedo, glm::vec3(0.8f));
  EXPECT_EQ(plain.T_world_model, glm::dmat4(1.0));
  EXPECT_FALSE(plain.bounce);
}

TEST_F(SceneManifest, DistantMapNeedsNoRoomAndDefaultsApply) {
  const Scene scene = load_scene(write(R"({"format": "lumar-scene", "version": 1,
    "environment_map": {"path": "maps/interior.exr", "distant": true},
    "movement_box": {"min": [0, 0, 0], "max": [0, 0, 0]}})"));
  EXPECT_TRUE(scene.distant_map);
  EXPECT_TRUE(scene.room_mesh.empty());
  EXPECT_DOUBLE_EQ(scene.room_scale, 1.0);
  EXPECT_DOUBLE_EQ(scene.azimuth_offset_deg, 0.0);
  EXPECT_EQ(scene.capture_position, glm::dvec3(0.0));
  EXPECT_TRUE(scene.objects.empty());
  EXPECT_EQ(scene.lighting.method, "volume");
  EXPECT_FALSE(scene.lighting.spacing.has_value());
}

TEST_F(SceneManifest, MalformedJsonGivesThePosition) {
  expect_error(write_changed("\"version\": 1,", "\"version\": 1,,"), "malformed JSON", "line 2");
}

// Numbers Embree aborted on (scale 1e300 or 1e-300, positions of 1e30) and a number
// that overflows a double (1e400, before: the library's raw text and exit 1) are each
// one error naming the manifest and the key.
TEST_F(SceneManifest, NumbersOutOfRangeAreRefusedAtTheParser) {
  expect_error(write_changed("\"scale\": 0.001", "\"scale\": 1e300"), "objects[0].pose.scale", "1e-6 to 1e6");
  expect_error(write_changed("\"scale\": 0.001", "\"scale\": 1e-300"), "objects[0].pose.scale", "1e-6 to 1e6");
  expect_error(write_changed("\"scale\": 0.01}", "\"scale\": 1e9}"), "room.scale", "1e-6 to 1e6");
  expect_error(write_changed("[0.5, 0.25, -0.75]", "[1e30, 0.25, -0.75]"), "objects[0].pose.translation", "10000 m");
  expect_error(write_changed("[0, 1.2, 0]", "[0, 1e30, 0]"), "environment_map.capture_position", "10000 m");
  expect_error(write_changed("\"max\": [1, 1, 1]", "\"max\": [1, 1, 1e5]"), "movement_box.max", "10000 m");
  expect_error(write_changed("[60, -60, -634]", "[6e12, -60, -634]"), "objects[0].pose.model_origin", "10 km");
  expect_error(write_changed("\"scale\": 0.001", "\"scale\": 1e400"), "malformed JSON", "number overflow");
}

TEST_F(SceneManifest, MissingManifestIsNamed) {
  try {
    load_scene(dir_ / "nope.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nope.json"), std::string::npos) << e.what();
  }
}

TEST_F(SceneManifest, RoomIsRequiredUnlessTheMapIsDistant) {
  expect_error(write_changed(R"("room": {"mesh": "room.obj", "scale": 0.01},)", ""), "room", "distant");
}

TEST_F(SceneManifest, BadAlbedo) {
  expect_error(write_changed("[0.8, 0.7, 0.6]", "[0.8, 1.5, 0.6]"), "objects[0].albedo",
               "expected 3 numbers in [0, 1]");
  expect_error(write_changed("[0.8, 0.7, 0.6]", "[0.8, 0.7]"), "objects[0].albedo");
  expect_error(write_changed("[0.8, 0.7, 0.6]", "\"grey\""), "objects[0].albedo");
  expect_error(write_changed("[0.8, 0.7, 0.6]", "[0.8, -0.1, 0.6]"), "objects[0].albedo");
}

TEST_F(SceneManifest, BadBounce) {
  expect_error(write_changed(R"("bounce": false)", R"("bounce": "no")"), "objects[1].bounce", "expected true or false");
  expect_error(write_changed(R"("bounce": false)", R"("bounce": 0)"), "objects[1].bounce");
}

TEST_F(SceneManifest, MissingReferencedFilesAreNamed) {
  expect_error(write_changed(R"("mesh": "figurine.ply")", R"("mesh": "lost.ply")"), "objects[0].mesh",
               (dir_ / "lost.ply").string());
  expect_error(write_changed("room.obj", "lost-room.obj"), "room.mesh", "lost-room.obj");
  expect_error(write_changed("maps/interior.exr", "maps/lost.exr"), "environment_map.path", "lost.exr");
}

TEST_F(SceneManifest, BadPoseValues) {
  expect_error(write_changed("[0, 2, 0]", "[0, 0, 0]"), "objects[0].pose.rotation_axis", "zero");
  expect_error(write_changed("\"scale\": 0.001", "\"scale\": 0"), "objects[0].pose.scale", "1e-6 to 1e6");
  expect_error(write_changed("[0.5, 0.25, -0.75]", "[0.5, 0.25]"), "objects[0].pose.translation");
}

TEST_F(SceneManifest, OtherStructuralErrors) {
  expect_error(write_changed("\"version\": 1", "\"version\": 2"), "version");
  expect_error(write_changed("\"lumar-scene\"", "\"other\""), "format");
  expect_error(write_changed("\"albedo\"", "\"albdeo\""), "objects[0].albdeo", "unknown key");
  expect_error(write_changed("\"min\": [-1, 0, -1]", "\"min\": [2, 0, -1]"), "movement_box", "min");
  expect_error(write_changed(R"("movement_box": {"min": [-1, 0, -1], "max": [1, 1, 1]},)", ""), "movement_box",
               "missing");
  expect_error(write_changed("\"capture_position\": [0, 1.2, 0], ", ""), "environment_map.capture_position");
  expect_error(write_changed(R"("name": "plain")", R"("name": "figurine")"), "objects[1].name", "figurine");
  const std::string lighting =
      R"("lighting": {"method": "sh9", "irradiance": {"spacing": 0.25, "rays_per_probe": 256, "refine": false}})";
  expect_error(write_changed(lighting, R"("lighting": 3)"), "lighting");
  // The lighting settings are typed like the rest: unknown keys, methods and bad values are named.
  expect_error(write_changed(lighting, R"("lighting": {"method": "sh9", "samples": 64})"), "lighting.samples",
               "unknown key");
  expect_error(write_changed(lighting, R"("lighting": {"method": "phong"})"), "lighting.method", "phong");
  expect_error(write_changed(lighting, R"("lighting": {"irradiance": {"spacing": 0}})"), "lighting.irradiance.spacing");
  expect_error(write_changed(lighting, R"("lighting": {"irradiance": {"rays_per_probe": 100.5}})"),
               "lighting.irradiance.rays_per_probe", "whole");
  expect_error(write_changed(lighting, R"("lighting": {"irradiance": {"refine": 1}})"), "lighting.irradiance.refine");
  expect_error(write_changed(lighting, R"("lighting": {"irradiance": {"shadow_map_resolution": 4}})"),
               "lighting.irradiance.shadow_map_resolution", "8 to 1024");
  EXPECT_EQ(load_scene(write_changed(lighting, R"("lighting": {"irradiance": {"shadow_map_resolution": 64}})"))
                .lighting.shadow_map_resolution,
            64);
  expect_error(write("[1, 2, 3]"), "top level");
}

}  // namespace
}  // namespace lumar
