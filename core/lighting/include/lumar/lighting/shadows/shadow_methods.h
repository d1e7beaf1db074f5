#pragma once
// Shadow attenuation (E_with / E_without per RGB channel) of receiver points by a
// scene's virtual objects, three ways:
//   lines     - this project's method: precomputed radiosity lines, culled by a shaft
//               hierarchy, traced against the objects' meshes (shadow_occlusion.h);
//   reference - brute force: one ray per emitter texel per point, against the proxy and
//               the objects' meshes (ground truth for the same emitters);
//   sphere    - the 2004 method: emitters thresholded to the map's bright parts, one line
//               per receiver and patch, blocked when it meets the object's bounding sphere.
#include <memory>
#include <string>
#include <vector>

#include "lumar/lighting/ray_scene.h"
#include "lumar/lighting/shadows/object_bounce.h"
#include "lumar/lighting/shadows/shadow_emitters.h"
#include "lumar/lighting/shadows/shadow_lines.h"
#include "lumar/scene/envmap.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/scene/mesh.h"

namespace lumar {

struct BoundingSphere {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
};
// Sphere around the posed mesh (centre of its world box, radius to the farthest vertex).
BoundingSphere bounding_sphere(const Mesh& model, const glm::dmat4& T_world_model);

// Exact visibility over every texel of `emitters` (ray per texel against the proxy and
// against `occluders`); parallel (TBB).
std::vector<glm::vec3> reference_attenuation(const std::vector<glm::vec3>& positions,
                                             const std::vector<glm::vec3>& normals, const Emitters& emitters,
                                             const RayScene& proxy, const RayScene& occluders);

// The 2004 baseline: `emitters` are the thresholded ones (one sample per patch).
std::vector<glm::vec3> sphere_attenuation(const std::vector<glm::vec3>& positions,
                                          const std::vector<glm::vec3>& normals, const Emitters& emitters,
                                          const RayScene& proxy, const std::vector<BoundingSphere>& occluders);

// Emitter settings of the 2004 baseline: texels above 4x the mean luminance, 50
// patches, one line per receiver and patch.
EmitterOptions sphere_baseline_emitter_options();

enum class ShadowMethod { Lines, Reference, Sphere };
// "lines", "reference" or "sphere"; throws InputError otherwise.
ShadowMethod parse_shadow_method(const std::string& name);

// What every method needs from a scene: the map, the proxy room (world, and as rays),
// the virtual objects in their poses.
class ShadowScene {
 public:
  using Object = LoadedObject;

  explicit ShadowScene(std::shared_ptr<const LoadedScene> scene);
  explicit ShadowScene(LoadedScene scene);
  // Parts built in code (tests): a map, a world-space proxy (may be empty), objects; the
  // movement box is the proxy's bounds.
  ShadowScene(EnvironmentMap map, bool distant, Mesh room_world, std::vector<Object> objects,
              ShadowRegions regions = {});

  const LoadedScene& scene() const { return *scene_; }
  const EnvironmentMap& map() const { return scene_->map; }
  bool distant() const { return scene_->distant(); }
  const Mesh& room() const { return scene_->room; }
  const RayScene& proxy() const { return *proxy_; }
  const std::vector<Object>& objects() const { return scene_->objects; }
  const ShadowRegions& regions() const { return scene_->manifest.shadows; }

  // Where shadows fall: the manifest's receiver boxes, or the floor under the movement box.
  std::vector<SceneBox> receiver_regions() const;
  // The receiver mesh over receiver_regions().
  Mesh receivers() const;
  // Emitters ranked for receivers around these points (their mean position and normal).
  Emitters emitters(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                    EmitterOptions options = {}) const;
  // The objects as Embree instances in their poses.
  std::unique_ptr<RayScene> occluders() const;

 private:
  std::shared_ptr<const LoadedScene> scene_;
  std::unique_ptr<RayScene> proxy_;
};

struct ShadowMethodOptions {
  EmitterOptions emitters;
  ShadowLineOptions lines;
  // Add the light the objects reflect onto the points (object_bounce.h; objects whose
  // manifest says "bounce": false reflect nothing). lines: the attenuation plus
  // ObjectBounce's ratio, the objects shaded by the scene's irradiance volume (or SH9)
  // and their baked self-occlusion, as in the overlay; reference: the composite's ground
  // truth (composite_reference.h, which integrates the room's radiance rather than the
  // emitters); sphere: InputError (the 2004 method had no bounce).
  bool bounce = false;
  BounceSettings bounce_settings;
  // Where the irradiance volume is cached (empty: the default); false: always built.
  bool volume_cache = true;
};

// InputError for options the method cannot honour (bounce with the sphere method), so a
// command can refuse them before it reads its inputs.
void check_shadow_options(ShadowMethod method, const ShadowMethodOptions& options);

// Attenuation of each point (unit normals) by the scene's objects in their poses:
// E_with / E_without per channel in [0, 1]; with bounce, (E_with + E_bounce) / E_without,
// which may exceed 1.
std::vector<glm::vec3> shadow_attenuation(const ShadowScene& scene, const std::vector<glm::vec3>& positions,
                                          const std::vector<glm::vec3>& normals, ShadowMethod method,
                                          const ShadowMethodOptions& options = {});

}  // namespace lumar
