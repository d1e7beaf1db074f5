#include "lumar/scene/loaded_scene.h"

#include <exception>
#include <future>
#include <limits>

#include <spdlog/spdlog.h>

#include <glm/gtc/matrix_transform.hpp>
#include <optional>

#include "lumar/base/error.h"

#include "decode_counter.h"

namespace lumar {

namespace {

// The highest point of the proxy straight below (x, z) and not above `from_y`, if any:
// a ray down, tested against every triangle (a proxy room is a few hundred of them).
std::optional<double> surface_below(const Mesh& room, double x, double z, double from_y) {
  std::optional<double> best;
  for (std::size_t t = 0; t + 2 < room.indices.size(); t += 3) {
    const glm::dvec3 a(room.positions[room.indices[t]]), b(room.positions[room.indices[t + 1]]),
        c(room.positions[room.indices[t + 2]]);
    // Barycentric coordinates of (x, z) in the triangle's projection on the floor plane.
    const double d = (b.z - c.z) * (a.x - c.x) + (c.x - b.x) * (a.z - c.z);
    if (std::abs(d) < 1e-12) continue;  // a wall, seen edge-on from above
    const double u = ((b.z - c.z) * (x - c.x) + (c.x - b.x) * (z - c.z)) / d;
    const double v = ((c.z - a.z) * (x - c.x) + (a.x - c.x) * (z - c.z)) / d;
    if (u < 0 || v < 0 || u + v > 1) continue;
    const double y = u * a.y + v * b.y + (1 - u - v) * c.y;
    if (y <= from_y + 1e-9 && (!best || y > *best)) best = y;
  }
  return best;
}

std::pair<glm::dvec3, glm::dvec3> posed_bounds(const Mesh& model, const glm::dmat4& T) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::vec3& p : model.positions) {
    const glm::dvec3 w(T * glm::dvec4(glm::dvec3(p), 1.0));
    lo = glm::min(lo, w), hi = glm::max(hi, w);
  }
  return {lo, hi};
}

bool inside(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& box_lo, const glm::dvec3& box_hi,
            double slack) {
  for (int a = 0; a < 3; ++a)
    if (lo[a] < box_lo[a] - slack || hi[a] > box_hi[a] + slack) return false;
  return true;
}

// The object's final pose: a bottom-centre origin and on_floor need its mesh and the
// proxy. `key`: the manifest key named in errors.
glm::dmat4 finish_pose(const ObjectPose& pose, const Mesh& model, const Mesh& room, const std::string& key) {
  glm::dmat4 T = pose_matrix(pose);
  if (!pose.model_origin) {
    // The middle of the bottom of the rotated, scaled model's box lands at `translation`.
    const glm::dmat4 RS = glm::mat4_cast(pose.rotation) * glm::scale(glm::dmat4(1.0), glm::dvec3(pose.scale));
    const auto [lo, hi] = posed_bounds(model, RS);
    const glm::dvec3 bottom_centre(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
    T = glm::translate(glm::dmat4(1.0), pose.translation - bottom_centre) * RS;
  }
  if (pose.on_floor) {
    const auto [lo, hi] = posed_bounds(model, T);
    const auto y = surface_below(room, 0.5 * (lo.x + hi.x), 0.5 * (lo.z + hi.z), hi.y);
    if (!y) throw InputError(key + ": on_floor: no proxy surface below the object; move it over the floor");
    T = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, *y - lo.y, 0.0)) * T;
  }
  return T;
}

// Warns when an object stands outside the movement box (its lighting is extrapolated
// there) or outside the room.
void warn_if_outside(const Scene& manifest, const Mesh& model, const glm::dmat4& T, const Mesh& room,
                     const std::string& key) {
  const auto [lo, hi] = posed_bounds(model, T);
  if (!inside(lo, hi, manifest.movement_min, manifest.movement_max, 1e-3))
    spdlog::warn("{}: stands outside the movement box, where its lighting is extrapolated", key);
  if (room.triangle_count() > 0) {
    glm::dvec3 room_lo(room.bounds().first), room_hi(room.bounds().second);
    // A flat proxy (a ground plane) is open along its normal: it bounds nothing there.
    for (int axis = 0; axis < 3; ++axis)
      if (room_hi[axis] - room_lo[axis] < 1e-6)
        room_lo[axis] = -std::numeric_limits<double>::infinity(),
        room_hi[axis] = std::numeric_limits<double>::infinity();
    if (!inside(lo, hi, room_lo, room_hi, 1e-3)) spdlog::warn("{}: reaches outside the proxy room", key);
  }
}

// The object's pose and its path's keys, finished.
void place_object(const Scene& manifest, std::size_t index, const SceneObject& o, const Mesh& room,
                  LoadedObject& object) {
  const std::string key = manifest.manifest.string() + ": objects[" + std::to_string(index) + "] (" + o.name + ")";
  std::vector<ObjectPath::Key> keys;
  for (std::size_t k = 0; k < o.path.size(); ++k) {
    const std::string key_k = key + ": path[" + std::to_string(k) + "]";
    keys.push_back({o.path[k].t_s, finish_pose(o.path[k].pose, object.model, room, key_k)});
    warn_if_outside(manifest, object.model, keys.back().T_world_model, room, key_k);
  }
  if (keys.empty()) {
    object.T_world_model = finish_pose(o.pose, object.model, room, key + ": pose");
    warn_if_outside(manifest, object.model, object.T_world_model, room, key);
    return;
  }
  const auto [lo, hi] = object.model.bounds();
  object.path = ObjectPath(std::move(keys), 0.5 * (glm::dvec3(lo) + glm::dvec3(hi)));
  object.T_world_model = object.path.keys().front().T_world_model;
}

}  // namespace

LoadedScene load_scene_files(const Scene& manifest) {
  LoadedScene out;
  out.manifest = manifest;
  // The map decodes on its own thread while the meshes do on this one.
  auto map = std::async(std::launch::async, [&] { return load_environment_map(manifest.environment_map); });
  std::exception_ptr meshes_error;
  try {
    if (!manifest.room_mesh.empty())
      out.room = transformed(load_mesh(manifest.room_mesh), glm::dmat4(glm::dmat3(manifest.room_scale)));
    // Objects that share a mesh file share one decode.
    std::map<std::filesystem::path, const Mesh*> decoded;
    out.objects.reserve(manifest.objects.size());  // the pointers above stay valid
    for (std::size_t i = 0; i < manifest.objects.size(); ++i) {
      const SceneObject& o = manifest.objects[i];
      LoadedObject object{o.name, {}, o.T_world_model, o.albedo, {}, o.bounce};
      if (const auto it = decoded.find(o.mesh); it != decoded.end())
        object.model = *it->second;
      else
        object.model = load_mesh(o.mesh);
      place_object(manifest, i, o, out.room, object);
      out.objects.push_back(std::move(object));
      decoded.emplace(o.mesh, &out.objects.back().model);
    }
  } catch (...) {
    meshes_error = std::current_exception();
  }
  out.map = map.get();  // a bad map is reported first, as when they were read in turn
  if (meshes_error) std::rethrow_exception(meshes_error);
  out.map.capture_position = manifest.capture_position;
  out.map.azimuth_offset_deg = manifest.azimuth_offset_deg;
  return out;
}

LoadedScene load_scene_files(const std::filesystem::path& manifest) { return load_scene_files(load_scene(manifest)); }

std::map<std::filesystem::path, int> scene_file_decodes() { return decode_counts(); }

}  // namespace lumar
