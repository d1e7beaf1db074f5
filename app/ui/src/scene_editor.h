#pragma once
// The scene as the window edits it: the loaded scene (what the compositor draws) and its
// typed manifest (what File > Save writes) kept in step, object for object, and where
// each object rests.
// Moves go straight to the compositor (its shadows follow within the frame); adding or
// removing an object, changing the lighting method or stopping an animated object swaps
// in a new scene (pipeline::Overlay::set_scene), whose irradiance volume comes from the
// cache.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "lumar/lighting/ray_scene.h"
#include "lumar/pipeline/overlay.h"
#include "lumar/scene/loaded_scene.h"
#include "lumar/ui/object_placement.h"

namespace lumar::ui {

class SceneEditor {
 public:
  explicit SceneEditor(pipeline::Overlay& overlay);

  const LoadedScene& scene() const { return scene_; }
  std::size_t object_count() const { return scene_.objects.size(); }
  const SurfacePoint& rest(std::size_t i) const { return rests_.at(i); }
  double scale_factor(std::size_t i) const { return scale_factors_.at(i); }
  const RayScene& proxy() const { return *proxy_; }

  // Where the object stands; an animated object stops following its path first.
  void set_pose(std::size_t i, const glm::dmat4& T_world_model, const SurfacePoint& rest);
  // Rests the object on the surface at `at`, keeping its turn and scale.
  void place(std::size_t i, const SurfacePoint& at);
  // Slides it by `offset` along its surface from where it was at `from`.
  void slide(std::size_t i, const glm::dmat4& from, const SurfacePoint& from_rest, const glm::dvec3& offset);
  void turn(std::size_t i, double degrees);
  // Scales it about its footprint, `factor` times its size when it was loaded or added.
  void set_scale_factor(std::size_t i, double factor);
  void set_albedo(std::size_t i, const glm::vec3& albedo);
  // Whether object i reflects light onto the room (the manifest's "bounce").
  void set_bounce(std::size_t i, bool on);
  // Loads a mesh (InputError when it does not load) and rests it at `at`, its bounding
  // box's diagonal 0.4 m; returns its index.
  std::size_t add(const std::filesystem::path& mesh, const SurfacePoint& at);
  void remove(std::size_t i);
  void set_lighting_method(const std::string& method);
  // Writes the edited scene (scene/scene_writer.h).
  void save(const std::filesystem::path& out) const;

 private:
  void rebuild();  // the compositor takes the scene as it is now
  pipeline::Overlay& overlay_;
  LoadedScene scene_;  // scene_.manifest.objects[i] is scene_.objects[i], T_world_model final
  std::vector<SurfacePoint> rests_;
  std::vector<double> scale_factors_;
  std::unique_ptr<RayScene> proxy_;
};

}  // namespace lumar::ui
