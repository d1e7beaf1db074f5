#include "scene_editor.h"

#include <glm/gtc/matrix_transform.hpp>

#include "lumar/base/error.h"
#include "lumar/scene/scene_writer.h"

namespace lumar::ui {

namespace {

// Where an object stands: the middle of the bottom of its world box, on a floor.
SurfacePoint footprint(const LoadedObject& o) {
  const auto [lo, hi] = transformed(o.model, o.T_world_model).bounds();
  return {glm::dvec3(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z)), glm::dvec3(0, 1, 0)};
}

}  // namespace

SceneEditor::SceneEditor(pipeline::Overlay& overlay) : overlay_(overlay), scene_(overlay.scene()) {
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
    scene_.manifest.objects[i].T_world_model = scene_.objects[i].T_world_model;
    rests_.push_back(footprint(scene_.objects[i]));
    scale_factors_.push_back(1.0);
  }
  proxy_ = std::make_unique<RayScene>();
  if (scene_.room.triangle_count() > 0) proxy_->add_static(scene_.room);
  proxy_->commit();
}

void SceneEditor::rebuild() { overlay_.set_scene(std::make_shared<const LoadedScene>(scene_)); }

void SceneEditor::set_pose(std::size_t i, const glm::dmat4& T_world_model, const SurfacePoint& rest) {
  LoadedObject& o = scene_.objects.at(i);
  o.T_world_model = T_world_model;
  scene_.manifest.objects[i].T_world_model = T_world_model;
  rests_[i] = rest;
  if (!o.path.empty()) {  // a placed object stands where it was put
    o.path = {};
    scene_.manifest.objects[i].path.clear();
    rebuild();
  } else {
    overlay_.compositor().set_object_pose(i, T_world_model);
  }
}

void SceneEditor::place(std::size_t i, const SurfacePoint& at) {
  const LoadedObject& o = scene_.objects.at(i);
  set_pose(i, rest_on_surface(o.model, glm::dmat3(o.T_world_model), at), at);
}

void SceneEditor::slide(std::size_t i, const glm::dmat4& from, const SurfacePoint& from_rest,
                        const glm::dvec3& offset) {
  SurfacePoint rest = from_rest;
  rest.point += offset;
  set_pose(i, glm::translate(glm::dmat4(1.0), offset) * from, rest);
}

void SceneEditor::turn(std::size_t i, double degrees) {
  set_pose(i, turn_on_surface(scene_.objects.at(i).T_world_model, rests_.at(i), degrees), rests_[i]);
}

void SceneEditor::set_scale_factor(std::size_t i, double factor) {
  if (!(factor > 0)) return;
  const LoadedObject& o = scene_.objects.at(i);
  const glm::dmat3 linear = glm::dmat3(o.T_world_model) * (factor / scale_factors_.at(i));
  scale_factors_[i] = factor;
  set_pose(i, rest_on_surface(o.model, linear, rests_[i]), rests_[i]);
}

void SceneEditor::set_bounce(std::size_t i, bool on) {
  scene_.objects.at(i).bounce = on;
  scene_.manifest.objects[i].bounce = on;
  overlay_.compositor().set_object_bounce(i, on);
}

void SceneEditor::set_albedo(std::size_t i, const glm::vec3& albedo) {
  scene_.objects.at(i).albedo = albedo;
  scene_.manifest.objects[i].albedo = albedo;
  overlay_.compositor().set_object_albedo(i, albedo);
}

std::size_t SceneEditor::add(const std::filesystem::path& mesh_path, const SurfacePoint& at) {
  Mesh mesh = load_mesh(mesh_path);  // InputError naming the file
  if (mesh.triangle_count() == 0) throw InputError(mesh_path.string() + ": the mesh has no triangles");
  const auto [lo, hi] = mesh.bounds();
  const double diagonal = glm::distance(glm::dvec3(lo), glm::dvec3(hi));
  if (!(diagonal > 0)) throw InputError(mesh_path.string() + ": the mesh has no extent");
  // A name of its own: the file's stem, numbered if taken.
  std::string name = mesh_path.stem().string();
  for (int n = 2;; ++n) {
    bool taken = false;
    for (const LoadedObject& o : scene_.objects) taken = taken || o.name == name;
    if (!taken) break;
    name = mesh_path.stem().string() + "-" + std::to_string(n);
  }
  const glm::dmat4 T = rest_on_surface(mesh, glm::dmat3(0.4 / diagonal), at);
  SceneObject entry;
  entry.name = name;
  entry.mesh = std::filesystem::absolute(mesh_path);
  entry.T_world_model = T;
  entry.albedo = glm::vec3(0.7f);
  scene_.manifest.objects.push_back(entry);
  scene_.objects.push_back(LoadedObject{name, std::move(mesh), T, entry.albedo, {}, entry.bounce});
  rests_.push_back(at);
  scale_factors_.push_back(1.0);
  rebuild();
  return scene_.objects.size() - 1;
}

void SceneEditor::remove(std::size_t i) {
  if (i >= scene_.objects.size()) return;
  scene_.objects.erase(scene_.objects.begin() + std::ptrdiff_t(i));
  scene_.manifest.objects.erase(scene_.manifest.objects.begin() + std::ptrdiff_t(i));
  rests_.erase(rests_.begin() + std::ptrdiff_t(i));
  scale_factors_.erase(scale_factors_.begin() + std::ptrdiff_t(i));
  rebuild();
}

void SceneEditor::set_lighting_method(const std::string& method) {
  if (method == scene_.manifest.lighting.method) return;
  scene_.manifest.lighting.method = method;
  rebuild();
}

void SceneEditor::save(const std::filesystem::path& out) const {
  if (out.empty()) throw InputError("save: give a file name for the scene");
  save_scene(scene_.manifest, out);
}

}  // namespace lumar::ui
