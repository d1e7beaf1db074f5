#pragma once
// The scene manifest (scene.json, format in docs/formats.md): the proxy room model,
// the environment map, the box where virtual objects may move, the virtual objects
// and the lighting settings. Relative paths are resolved against the manifest's folder.
#include <array>
#include <filesystem>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <optional>
#include <string>
#include <vector>

namespace lumar {

// Ranges every manifest number is held to before it reaches Embree, OpenGL or an
// allocator (docs/formats.md): positions in metres within ±10 km of the origin on each
// axis, scale factors from 1e-6 to 1e6. Beyond them rays lose their float precision;
// Embree aborted on a scale of 1e300 and on positions of 1e30.
inline constexpr double kMaxCoordinateM = 1e4;
inline constexpr double kMinScale = 1e-6, kMaxScale = 1e6;

// Where an object stands (manifest key "pose", docs/formats.md). The rotation is given
// as an axis and an angle, as yaw, pitch and roll, or as a quaternion.
struct ObjectPose {
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  double scale = 1.0;
  // The model point that lands at `translation`; nullopt: "bottom-centre", the middle of
  // the bottom of the rotated, scaled model's bounding box (known once the mesh is read).
  std::optional<glm::dvec3> model_origin = glm::dvec3(0.0);
  bool on_floor = false;  // moved up or down until its lowest point rests on the proxy below it
};

// translate(translation) * R * scale * translate(-model_origin); a bottom-centre origin
// counts as (0, 0, 0) here, and on_floor is not applied (both need the mesh).
glm::dmat4 pose_matrix(const ObjectPose& pose);

// One key of an animated object's path (manifest key "path", docs/formats.md): where the
// object stands at t seconds of recording time. Its scale, model origin and on_floor
// are the object's pose's; its rotation is the key's turn times the pose's rotation.
struct PathKey {
  double t_s = 0.0;
  ObjectPose pose;
};

struct SceneObject {
  std::string name;
  std::filesystem::path mesh;
  ObjectPose pose;
  std::vector<PathKey> path;  // empty: the object stands still at `pose`
  // pose_matrix(pose): load_scene_files (loaded_scene.h) finishes a bottom-centre origin
  // and on_floor, which need the mesh.
  glm::dmat4 T_world_model{1.0};
  glm::vec3 albedo{0.8f};
  bool bounce = true;  // it reflects light onto the real surfaces (docs/shadows.md, "Bounce")
};

// An axis-aligned world box (metres) marking a region of the proxy room.
struct SceneBox {
  glm::dvec3 min{0.0}, max{0.0};
  bool contains(const glm::dvec3& p) const {
    return p.x >= min.x && p.y >= min.y && p.z >= min.z && p.x <= max.x && p.y <= max.y && p.z <= max.z;
  }
};

// Where shadows fall and where their light comes from (manifest key "shadows",
// docs/shadows.md). Empty lists mean the defaults: the floor under the movement box
// receives, and every texel of the map emits.
struct ShadowRegions {
  std::vector<SceneBox> receivers;  // proxy surfaces inside these boxes receive shadows
  std::vector<SceneBox> emitters;   // only map light landing on the proxy inside these boxes emits
  int receiver_vertices = 3200;     // about this many receiver vertices, spread uniformly
};

// The bounds of lighting.irradiance.shadow_map_resolution, texels per side (also the
// overlay's --shadow-map).
inline constexpr int kMinShadowMapResolution = 8, kMaxShadowMapResolution = 1024;

// The manifest's "lighting": how the virtual objects are shaded (docs/irradiance.md).
struct LightingSettings {
  std::string method = "volume";  // one of kLightingMethods
  // "irradiance": the volume's quality knobs; those not given keep the method's defaults.
  std::optional<double> spacing;
  std::optional<int> rays_per_probe, octahedral_resolution, max_lights, shadow_map_resolution;
  std::optional<bool> refine, visibility;
};
// volume: the irradiance volume (SH9 + an octahedral correction + exact dominant lights);
// sh9: nine SH coefficients for the whole scene; octahedral, lights: the volume with one
// representation; greger2004: the 2004 baseline.
inline constexpr std::array<const char*, 5> kLightingMethods{"volume", "sh9", "octahedral", "lights", "greger2004"};

struct Scene {
  std::filesystem::path manifest;
  std::filesystem::path room_mesh;
  double room_scale = 1.0;  // room model units to metres
  std::filesystem::path environment_map;
  glm::dvec3 capture_position{0.0};
  double azimuth_offset_deg = 0.0;
  bool distant_map = false;  // map at infinity: no proxy needed for lighting
  glm::dvec3 movement_min{0.0}, movement_max{0.0};
  std::vector<SceneObject> objects;
  LightingSettings lighting;
  ShadowRegions shadows;
};

// Throws InputError naming the manifest (and the key) on missing files, malformed
// JSON, missing keys or bad values.
Scene load_scene(const std::filesystem::path& manifest);

}  // namespace lumar
