#include "lumar/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "lumar/base/error.h"
#include "lumar/base/input_file.h"
#include "lumar/base/json_file.h"
#include "lumar/base/pose.h"

namespace lumar {

namespace {

using nlohmann::json;

// Reads one manifest; every complaint names the manifest and the key path.
class ManifestReader {
 public:
  explicit ManifestReader(std::filesystem::path manifest)
      : manifest_(std::move(manifest)), folder_(manifest_.parent_path()) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(manifest_.string() + ": " + key + ": " + what);
  }

  // Rejects keys the format does not define, so that a typo is not silently ignored.
  void only_keys(const json& object, const std::string& key, std::initializer_list<const char*> known) const {
    for (const auto& item : object.items()) {
      bool ok = false;
      for (const char* k : known) ok = ok || item.key() == k;
      if (!ok) {
        std::string list;
        for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
        fail(join(key, item.key()), "unknown key (expected one of: " + list + ")");
      }
    }
  }

  static std::string join(const std::string& parent, const std::string& child) {
    return parent.empty() ? child : parent + "." + child;
  }

  const json& object(const json& parent, const std::string& parent_key, const char* name) const {
    const std::string key = join(parent_key, name);
    if (!parent.contains(name)) fail(key, "missing (see docs/formats.md, \"Scene manifest\")");
    const json& v = parent.at(name);
    if (!v.is_object()) fail(key, "expected an object");
    return v;
  }

  double number(const json& v, const std::string& key) const {
    if (!v.is_number()) fail(key, "expected a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(key, "expected a finite number");
    return d;
  }

  double number_or(const json& parent, const std::string& parent_key, const char* name, double fallback) const {
    return parent.contains(name) ? number(parent.at(name), join(parent_key, name)) : fallback;
  }

  glm::dvec3 vec3(const json& v, const std::string& key, const char* what = "expected 3 numbers") const {
    if (!v.is_array() || v.size() != 3) fail(key, what);
    glm::dvec3 out;
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number() || !std::isfinite(v[i].get<double>())) fail(key, what);
      out[i] = v[i].get<double>();
    }
    return out;
  }

  // A position in metres: within kMaxCoordinateM of the origin on each axis, so that
  // rays and matrices built from it stay far from float overflow (docs/formats.md).
  glm::dvec3 position(const json& v, const std::string& key) const {
    const glm::dvec3 p = vec3(v, key);
    for (int i = 0; i < 3; ++i)
      if (std::abs(p[i]) > kMaxCoordinateM)
        fail(key, "expected coordinates within ±" + std::to_string(int(kMaxCoordinateM)) + " m of the origin");
    return p;
  }

  glm::dvec3 position_or(const json& parent, const std::string& parent_key, const char* name,
                         glm::dvec3 fallback) const {
    return parent.contains(name) ? position(parent.at(name), join(parent_key, name)) : fallback;
  }

  // A scale factor from model units to metres, within kMinScale..kMaxScale.
  double scale_or(const json& parent, const std::string& parent_key, const char* name) const {
    const double s = number_or(parent, parent_key, name, 1.0);
    if (!(s >= kMinScale && s <= kMaxScale)) fail(join(parent_key, name), "expected a number from 1e-6 to 1e6");
    return s;
  }

  glm::dvec3 vec3_or(const json& parent, const std::string& parent_key, const char* name, glm::dvec3 fallback) const {
    return parent.contains(name) ? vec3(parent.at(name), join(parent_key, name)) : fallback;
  }

  bool boolean_or(const json& parent, const std::string& parent_key, const char* name, bool fallback) const {
    if (!parent.contains(name)) return fallback;
    if (!parent.at(name).is_boolean()) fail(join(parent_key, name), "expected true or false");
    return parent.at(name).get<bool>();
  }

  std::string string(const json& parent, const std::string& parent_key, const char* name) const {
    const std::string key = join(parent_key, name);
    if (!parent.contains(name)) fail(key, "missing");
    const json& v = parent.at(name);
    if (!v.is_string() || v.get<std::string>().empty()) fail(key, "expected a non-empty string");
    return v.get<std::string>();
  }

  // A path relative to the manifest's folder; the file must exist.
  std::filesystem::path existing_file(const json& parent, const std::string& parent_key, const char* name) const {
    const std::filesystem::path given = string(parent, parent_key, name);
    const std::filesystem::path resolved = (folder_ / given).lexically_normal();
    if (const auto problem = input_file_problem(resolved))
      fail(join(parent_key, name), resolved.string() + " " + *problem);
    return resolved;
  }

 private:
  std::filesystem::path manifest_;
  std::filesystem::path folder_;
};

std::string fmt_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

json parse_manifest(const std::filesystem::path& manifest) { return read_json_file(manifest, "scene manifest"); }

// One rotation, given as rotation_axis + rotation_deg | yaw_pitch_roll_deg |
// rotation_wxyz; `fallback` when none is given.
glm::dquat read_rotation(const ManifestReader& r, const json& v, const std::string& pk, const glm::dquat& fallback) {
  const bool axis_angle = v.contains("rotation_axis") || v.contains("rotation_deg");
  const int forms = int(axis_angle) + int(v.contains("yaw_pitch_roll_deg")) + int(v.contains("rotation_wxyz"));
  if (forms > 1) r.fail(pk, "give one rotation: rotation_axis and rotation_deg, yaw_pitch_roll_deg, or rotation_wxyz");
  if (axis_angle) {
    const glm::dvec3 axis = r.vec3_or(v, pk, "rotation_axis", glm::dvec3(0.0, 1.0, 0.0));
    if (glm::length(axis) < 1e-9) r.fail(pk + ".rotation_axis", "must not be the zero vector");
    return axis_angle_deg(axis, r.number_or(v, pk, "rotation_deg", 0.0));
  }
  if (v.contains("yaw_pitch_roll_deg")) {
    // Yaw about world +Y (up), then pitch about +X, then roll about +Z: R = Ry Rx Rz.
    const glm::dvec3 a = r.vec3(v.at("yaw_pitch_roll_deg"), pk + ".yaw_pitch_roll_deg");
    return axis_angle_deg({0, 1, 0}, a.x) * axis_angle_deg({1, 0, 0}, a.y) * axis_angle_deg({0, 0, 1}, a.z);
  }
  if (v.contains("rotation_wxyz")) {
    const json& q = v.at("rotation_wxyz");
    const char* what = "expected a unit quaternion [w, x, y, z]";
    if (!q.is_array() || q.size() != 4) r.fail(pk + ".rotation_wxyz", what);
    double c[4];
    for (int i = 0; i < 4; ++i) c[i] = r.number(q[std::size_t(i)], pk + ".rotation_wxyz");
    const glm::dquat rotation(c[0], c[1], c[2], c[3]);
    if (std::abs(glm::length(rotation) - 1.0) > 1e-3) r.fail(pk + ".rotation_wxyz", what);
    return glm::normalize(rotation);
  }
  return fallback;
}

// "pose": translation, a rotation (read_rotation), scale, model_origin ([x, y, z] or
// "bottom-centre"), on_floor.
ObjectPose read_pose(const ManifestReader& r, const json& pose, const std::string& pk) {
  r.only_keys(pose, pk,
              {"translation", "rotation_axis", "rotation_deg", "yaw_pitch_roll_deg", "rotation_wxyz", "scale",
               "model_origin", "on_floor"});
  ObjectPose p;
  p.translation = r.position_or(pose, pk, "translation", p.translation);
  p.rotation = read_rotation(r, pose, pk, p.rotation);
  p.scale = r.scale_or(pose, pk, "scale");
  if (pose.contains("model_origin")) {
    const json& origin = pose.at("model_origin");
    if (origin.is_string()) {
      if (origin.get<std::string>() != "bottom-centre")
        r.fail(pk + ".model_origin", "expected [x, y, z] or \"bottom-centre\"");
      p.model_origin = std::nullopt;
    } else {
      p.model_origin = r.vec3(origin, pk + ".model_origin", "expected [x, y, z] or \"bottom-centre\"");
      // Model units: in metres it is scale times this.
      if (glm::length(*p.model_origin) * p.scale > kMaxCoordinateM)
        r.fail(pk + ".model_origin", "lies more than 10 km from the model's origin once scaled");
    }
  }
  p.on_floor = r.boolean_or(pose, pk, "on_floor", false);
  return p;
}

// "path": timed key poses, t strictly increasing; each key's translation replaces the
// pose's, and its rotation turns the posed object (R_key · R_pose).
std::vector<PathKey> read_path(const ManifestReader& r, const json& v, const std::string& key, const ObjectPose& pose) {
  const char* what = "expected an array of at least 2 keys {\"t\": s, \"translation\": [x, y, z], rotation}";
  if (!v.is_array() || v.size() < 2) r.fail(key, what);
  std::vector<PathKey> keys;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string k = key + "[" + std::to_string(i) + "]";
    if (!v[i].is_object()) r.fail(k, what);
    r.only_keys(v[i], k, {"t", "translation", "rotation_axis", "rotation_deg", "yaw_pitch_roll_deg", "rotation_wxyz"});
    if (!v[i].contains("t")) r.fail(k + ".t", "missing (seconds of recording time)");
    if (!v[i].contains("translation")) r.fail(k + ".translation", "missing");
    PathKey p{r.number(v[i].at("t"), k + ".t"), pose};
    if (p.t_s < 0 || p.t_s > 1e6) r.fail(k + ".t", "expected seconds from 0 to 1e6");
    if (!keys.empty() && p.t_s <= keys.back().t_s) r.fail(k + ".t", "must be later than the key before");
    p.pose.translation = r.position(v[i].at("translation"), k + ".translation");
    p.pose.rotation = glm::normalize(read_rotation(r, v[i], k, glm::dquat(1.0, 0.0, 0.0, 0.0)) * pose.rotation);
    keys.push_back(p);
  }
  return keys;
}

SceneObject read_object(const ManifestReader& r, const json& v, const std::string& key) {
  if (!v.is_object()) r.fail(key, "expected an object");
  r.only_keys(v, key, {"name", "mesh", "albedo", "bounce", "pose", "path"});
  SceneObject object;
  object.name = r.string(v, key, "name");
  object.mesh = r.existing_file(v, key, "mesh");
  if (v.contains("albedo")) {
    const char* what = "expected 3 numbers in [0, 1]";
    const glm::dvec3 a = r.vec3(v.at("albedo"), key + ".albedo", what);
    for (int i = 0; i < 3; ++i)
      if (a[i] < 0.0 || a[i] > 1.0) r.fail(key + ".albedo", what);
    object.albedo = glm::vec3(a);
  }
  object.bounce = r.boolean_or(v, key, "bounce", true);

  if (v.contains("pose")) object.pose = read_pose(r, r.object(v, key, "pose"), key + ".pose");
  object.T_world_model = pose_matrix(object.pose);
  if (v.contains("path")) object.path = read_path(r, v.at("path"), key + ".path", object.pose);
  return object;
}

std::vector<SceneBox> read_boxes(const ManifestReader& r, const json& parent, const std::string& parent_key,
                                 const char* name) {
  std::vector<SceneBox> boxes;
  if (!parent.contains(name)) return boxes;
  const std::string key = ManifestReader::join(parent_key, name);
  const json& list = parent.at(name);
  if (!list.is_array()) r.fail(key, "expected an array of {\"min\": [x, y, z], \"max\": [x, y, z]} boxes");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string k = key + "[" + std::to_string(i) + "]";
    if (!list[i].is_object()) r.fail(k, "expected an object with min and max");
    r.only_keys(list[i], k, {"min", "max"});
    if (!list[i].contains("min")) r.fail(k + ".min", "missing");
    if (!list[i].contains("max")) r.fail(k + ".max", "missing");
    SceneBox b{r.vec3(list[i].at("min"), k + ".min"), r.vec3(list[i].at("max"), k + ".max")};
    for (int a = 0; a < 3; ++a)
      if (b.min[a] > b.max[a]) r.fail(k, "min must not exceed max on any axis");
    boxes.push_back(b);
  }
  return boxes;
}

LightingSettings read_lighting(const ManifestReader& r, const json& doc) {
  LightingSettings out;
  if (!doc.contains("lighting")) return out;
  const json& v = r.object(doc, "", "lighting");
  r.only_keys(v, "lighting", {"method", "irradiance"});
  if (v.contains("method")) {
    out.method = r.string(v, "lighting", "method");
    if (std::find(kLightingMethods.begin(), kLightingMethods.end(), out.method) == kLightingMethods.end()) {
      std::string list;
      for (const char* m : kLightingMethods) list += std::string(list.empty() ? "" : ", ") + m;
      r.fail("lighting.method", "unknown method \"" + out.method + "\" (expected one of: " + list + ")");
    }
  }
  if (!v.contains("irradiance")) return out;
  const json& q = r.object(v, "lighting", "irradiance");
  const std::string k = "lighting.irradiance";
  r.only_keys(q, k,
              {"spacing", "rays_per_probe", "octahedral_resolution", "max_lights", "shadow_map_resolution", "refine",
               "visibility"});
  const auto in_range = [&](const char* name, double lo, double hi) -> std::optional<double> {
    if (!q.contains(name)) return std::nullopt;
    const double d = r.number(q.at(name), k + "." + name);
    if (d < lo || d > hi) r.fail(k + "." + name, "expected a number from " + fmt_number(lo) + " to " + fmt_number(hi));
    return d;
  };
  const auto integer = [&](const char* name, int lo, int hi) -> std::optional<int> {
    const auto d = in_range(name, lo, hi);
    if (d && *d != std::floor(*d)) r.fail(k + "." + name, "expected a whole number");
    return d ? std::optional<int>(int(*d)) : std::nullopt;
  };
  out.spacing = in_range("spacing", 0.02, 100.0);
  out.rays_per_probe = integer("rays_per_probe", 16, 65536);
  out.octahedral_resolution = integer("octahedral_resolution", 2, 64);
  out.max_lights = integer("max_lights", 0, 32);
  out.shadow_map_resolution = integer("shadow_map_resolution", kMinShadowMapResolution, kMaxShadowMapResolution);
  if (q.contains("refine")) out.refine = r.boolean_or(q, k, "refine", true);
  if (q.contains("visibility")) out.visibility = r.boolean_or(q, k, "visibility", true);
  return out;
}

ShadowRegions read_shadows(const ManifestReader& r, const json& doc) {
  ShadowRegions out;
  if (!doc.contains("shadows")) return out;
  const json& v = r.object(doc, "", "shadows");
  r.only_keys(v, "shadows", {"receivers", "emitters", "receiver_vertices"});
  out.receivers = read_boxes(r, v, "shadows", "receivers");
  out.emitters = read_boxes(r, v, "shadows", "emitters");
  if (v.contains("receiver_vertices")) {
    const json& n = v.at("receiver_vertices");
    if (!n.is_number_integer() || n.get<long long>() < 4 || n.get<long long>() > 1000000)
      r.fail("shadows.receiver_vertices", "expected an integer from 4 to 1000000");
    out.receiver_vertices = int(n.get<long long>());
  }
  return out;
}

}  // namespace

glm::dmat4 pose_matrix(const ObjectPose& p) {
  return glm::translate(glm::dmat4(1.0), p.translation) * glm::mat4_cast(p.rotation) *
         glm::scale(glm::dmat4(1.0), glm::dvec3(p.scale)) *
         glm::translate(glm::dmat4(1.0), -p.model_origin.value_or(glm::dvec3(0.0)));
}

Scene load_scene(const std::filesystem::path& manifest) {
  const json doc = parse_manifest(manifest);
  const ManifestReader r(manifest);
  if (!doc.is_object()) r.fail("(top level)", "expected a JSON object");
  r.only_keys(doc, "",
              {"format", "version", "room", "environment_map", "movement_box", "objects", "lighting", "shadows"});

  if (!doc.contains("format") || doc.at("format") != "lumar-scene") r.fail("format", "expected \"lumar-scene\"");
  if (!doc.contains("version") || !doc.at("version").is_number_integer()) r.fail("version", "expected an integer");
  if (doc.at("version").get<long long>() != 1)
    r.fail("version", "this build reads version 1; update lumar or convert the manifest");

  Scene scene;
  scene.manifest = manifest;

  const json& env = r.object(doc, "", "environment_map");
  r.only_keys(env, "environment_map", {"path", "capture_position", "azimuth_offset_deg", "distant"});
  scene.environment_map = r.existing_file(env, "environment_map", "path");
  scene.distant_map = r.boolean_or(env, "environment_map", "distant", false);
  scene.azimuth_offset_deg = r.number_or(env, "environment_map", "azimuth_offset_deg", 0.0);
  // A distant map is at infinity, so where it was captured does not matter.
  if (!scene.distant_map && !env.contains("capture_position"))
    r.fail("environment_map.capture_position", "missing (required unless \"distant\": true)");
  scene.capture_position = r.position_or(env, "environment_map", "capture_position", glm::dvec3(0.0));

  // The proxy room gives the map's parallax and the surfaces shadows fall on; only a
  // distant map can do without it.
  if (doc.contains("room")) {
    const json& room = r.object(doc, "", "room");
    r.only_keys(room, "room", {"mesh", "scale"});
    scene.room_mesh = r.existing_file(room, "room", "mesh");
    scene.room_scale = r.scale_or(room, "room", "scale");
  } else if (!scene.distant_map) {
    r.fail("room", "missing (required unless environment_map.distant is true)");
  }

  const json& box = r.object(doc, "", "movement_box");
  r.only_keys(box, "movement_box", {"min", "max"});
  if (!box.contains("min")) r.fail("movement_box.min", "missing");
  if (!box.contains("max")) r.fail("movement_box.max", "missing");
  scene.movement_min = r.position(box.at("min"), "movement_box.min");
  scene.movement_max = r.position(box.at("max"), "movement_box.max");
  for (int i = 0; i < 3; ++i)
    if (scene.movement_min[i] > scene.movement_max[i]) r.fail("movement_box", "min must not exceed max on any axis");

  if (doc.contains("objects")) {
    const json& objects = doc.at("objects");
    if (!objects.is_array()) r.fail("objects", "expected an array");
    std::set<std::string> names;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const std::string key = "objects[" + std::to_string(i) + "]";
      scene.objects.push_back(read_object(r, objects[i], key));
      if (!names.insert(scene.objects.back().name).second)
        r.fail(key + ".name", "\"" + scene.objects.back().name + "\" is used by an earlier object");
    }
  }

  scene.lighting = read_lighting(r, doc);
  scene.shadows = read_shadows(r, doc);
  return scene;
}

}  // namespace lumar
