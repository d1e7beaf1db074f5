#include "lumar/render/compositor.h"

#include <spdlog/spdlog.h>

#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <memory>

#include "lumar/base/error.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/lighting/irradiance_volume.h"
#include "lumar/lighting/light_self_shadow.h"
#include "lumar/lighting/self_occlusion.h"
#include "lumar/lighting/shadows/contact_receivers.h"
#include "lumar/lighting/shadows/object_bounce.h"
#include "lumar/lighting/shadows/object_shadows.h"
#include "lumar/lighting/shadows/shadow_line_cache.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/lighting/vertex_irradiance.h"

namespace lumar {

struct Compositor::SphereShadows {
  Mesh receivers;
  Emitters emitters;
  std::vector<glm::dmat4> poses;  // at the last trace; empty: never traced
  std::vector<glm::vec3> attenuation;
};

// The contact receivers for the poses they were built at, their lines, the correction
// they draw over the receivers' shadow, and where they are drawn: carried with the
// objects to their poses now (ContactPatch::carried).
struct Compositor::ContactShadows {
  std::vector<glm::dmat4> poses;
  ContactPatch patch;  // empty: no object touches a receiver surface
  std::unique_ptr<LineShadows> lines;
  std::vector<glm::vec3> correction;
  std::vector<glm::vec3> built_correction;  // at `poses`
  std::vector<glm::dmat4> drawn_poses;
  ContactPatch drawn;
};

// The receivers' shadow lines, the light the objects reflect onto them, and with two
// objects or more their shadows on each other: CPU work, on a worker thread.
struct Compositor::ReceiverShadows {
  Mesh receivers;
  std::shared_ptr<const Emitters> emitters;
  std::shared_ptr<LineShadows> lines;     // null without receivers
  std::shared_ptr<ObjectBounce> bounce;   // with the lines
  std::shared_ptr<ObjectShadows> object_shadows;  // null with fewer than two objects
  std::chrono::steady_clock::time_point started;
};

// The compositor's work off the calling thread (the shadows at start-up, the contact
// patch), as TBB tasks: run on TBB's own worker threads, or by a thread that waits on
// the group, never on a thread of its own (threads that come and go between TBB's loops
// pass its task memory between them where ThreadSanitizer cannot see it). A task owns
// what it reads; its result comes back through a std::future.
struct Compositor::Workers {
  tbb::task_group group;
  template <class F>
  auto run(F work) -> std::future<decltype(work())> {
    auto task = std::make_shared<std::packaged_task<decltype(work())()>>(std::move(work));
    auto result = task->get_future();
    group.run([task] { (*task)(); });  // an exception goes to the future
    return result;
  }
  // The result of run(), this thread running the group's tasks meanwhile: with one core
  // TBB has no worker thread, and only a thread that waits on the group runs them.
  template <class T>
  T get(std::future<T>& result) {
    group.wait();
    return result.get();
  }
  ~Workers() { group.wait(); }
};

const LineShadows* Compositor::contact_shadows() const { return contact_ ? contact_->lines.get() : nullptr; }

const Mesh* Compositor::contact_receivers() const {
  return contact_ && contact_->lines && !contact_->drawn.empty() ? &contact_->drawn.receivers : nullptr;
}

namespace {

void check(const ShadowQuality& quality) {
  if (quality.emitter_patches < 1 || quality.lines_per_patch < 1)
    throw InputError("shadow quality: emitter patches and lines per patch must be at least 1");
}

}  // namespace

Compositor::Compositor(std::shared_ptr<const LoadedScene> scene, const CameraIntrinsics& output_camera,
                       const cv::Mat& map_x, const cv::Mat& map_y, const CompositorSettings& settings)
    : camera_(output_camera.without_distortion()),
      scene_(std::move(scene)),
      cache_(settings.cache),
      workers_(std::make_unique<Workers>()),
      shadow_quality_(settings.shadows) {
  check(shadow_quality_);
  const LoadedScene& s = *scene_;
  for (const LoadedObject& object : s.objects) poses_.push_back(object.T_world_model);
  // The shadows are traced (or loaded) on worker threads while the renderer is set up here.
  std::future<ReceiverShadows> shadows = start_shadows(settings.features);
  sh_ = project_radiance_sh9(s.map);
  renderer_ = std::make_unique<gl::Renderer>(camera_);
  renderer_->set_features(settings.features);
  if (s.room.triangle_count() > 0) renderer_->set_room(s.room);
  // Spatially varying light: the irradiance volume over the movement box (cached on disk).
  if (const std::string& method = s.manifest.lighting.method; method != "sh9") {
    bool loaded = false;
    volume_ = std::make_shared<const IrradianceVolume>(scene_irradiance_volume(s, method, cache_, {}, &loaded));
    renderer_->set_irradiance_volume(volume_.get());
    spdlog::debug("irradiance volume ({}): {} probes, {}", volume_->settings().describe(), volume_->stats().probes,
                  loaded ? "loaded from the cache" : "built");
  }
  renderer_->set_environment(s.map);
  if (!map_x.empty()) renderer_->set_undistortion_map(map_x, map_y);

  for (const LoadedObject& object : s.objects) {
    const int id = renderer_->add_object(object.model);
    renderer_->set_object_pose(id, object.T_world_model);
    renderer_->set_object_material(id, object.albedo, sh_);
    // Every k-th vertex, so that checks see the whole object at a bounded cost.
    const Mesh& mesh = object.model;
    const std::size_t step = std::max<std::size_t>(1, mesh.positions.size() / 200);
    albedo_.push_back(object.albedo);
    sampled_points_.emplace_back();
    for (std::size_t i = 0; i < mesh.positions.size(); i += step)
      sampled_points_.back().emplace_back(mesh.positions[i]);
    spdlog::debug("object '{}': {} triangles", object.name, mesh.triangle_count());
  }
  vertex_light_stale_.assign(s.objects.size(), 1);
  lights_blocked_.assign(s.objects.size(), {});
  lights_blocked_stale_.assign(s.objects.size(), 1);
  pose_object_points();
  if (settings.features.self_occlusion) bake_self_occlusion_once();
  take_shadows(workers_->get(shadows));  // this thread helps, with the contact patch too if it started
}

Compositor::~Compositor() = default;

void Compositor::pose_object_points() {
  object_points_.clear();
  for (std::size_t i = 0; i < poses_.size(); ++i)
    for (const glm::dvec3& p : sampled_points_[i]) object_points_.push_back(glm::dvec3(poses_[i] * glm::dvec4(p, 1.0)));
}

void Compositor::bake_self_occlusion_once() {
  if (!self_occlusion_.empty() || scene_->objects.empty()) return;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < scene_->objects.size(); ++i) {
    // One ray scene of the mesh for both: the open share and the exact lights' shadow.
    light_self_shadow_.push_back(std::make_shared<const LightSelfShadow>(scene_->objects[i].model));
    self_occlusion_.push_back(bake_self_occlusion(scene_->objects[i].model, light_self_shadow_.back()->scene()));
    renderer_->set_object_self_occlusion(int(i), self_occlusion_.back());
  }
  spdlog::debug("self-occlusion baked in {:.0f} ms",
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
}

// The bounce shades the objects as the renderer does: with their self-occlusion when it is on.
void Compositor::give_bounce_occlusion() {
  if (!bounce_) return;
  const bool on = renderer_->features().self_occlusion && !self_occlusion_.empty();
  for (std::size_t i = 0; i < scene_->objects.size(); ++i)
    bounce_->set_object_occlusion(
        int(i), on ? std::span<const VertexOcclusion>(self_occlusion_[i]) : std::span<const VertexOcclusion>());
}

void Compositor::set_features(const gl::CompositeFeatures& features) {
  if (features.self_occlusion) bake_self_occlusion_once();
  const gl::CompositeFeatures before = renderer_->features();
  renderer_->set_features(features);
  if (before.self_occlusion != features.self_occlusion) {
    give_bounce_occlusion();
    std::fill(vertex_light_stale_.begin(), vertex_light_stale_.end(), 1);
    std::fill(lights_blocked_stale_.begin(), lights_blocked_stale_.end(), 1);
  }
  if (before.bounce != features.bounce || before.lines != features.lines) shadows_uploaded_ = false;
  if (before.lines != features.lines || before.contact != features.contact) contact_uploaded_ = false;
}

const ShadowScene& Compositor::shadow_scene() {
  if (!shadow_scene_) shadow_scene_ = std::make_shared<const ShadowScene>(scene_);
  return *shadow_scene_;
}

// Ranks the emitters for the scene's receivers (the objects are the occluders), starts the
// contact build, and the lines' trace or load on a worker thread; take_shadows takes them.
std::future<Compositor::ReceiverShadows> Compositor::start_shadows(const gl::CompositeFeatures& features) {
  const auto t0 = std::chrono::steady_clock::now();
  const ShadowScene& shadow_scene = this->shadow_scene();
  const auto& objects = shadow_scene.objects();
  const Mesh receivers = shadow_scene.receivers();
  const bool on_receivers = receivers.triangle_count() > 0 && !objects.empty();
  if (!on_receivers && objects.size() < 2) return workers_->run([] { return ReceiverShadows{}; });
  // Emitters ranked for the receivers or, without any, for the objects' own surfaces.
  Mesh around = receivers;
  if (!on_receivers)
    for (const auto& o : objects) {
      const Mesh posed = transformed(o.model, o.T_world_model);
      around.positions.insert(around.positions.end(), posed.positions.begin(), posed.positions.end());
      around.normals.insert(around.normals.end(), posed.normals.begin(), posed.normals.end());
    }
  EmitterOptions options;
  options.max_patches = shadow_quality_.emitter_patches;
  options.samples_per_patch = shadow_quality_.lines_per_patch;
  auto emitters = std::make_shared<const Emitters>(shadow_scene.emitters(around.positions, around.normals, options));
  if (on_receivers) {
    receivers_ = receivers, emitters_ = emitters;
    start_contact_build(features);  // it needs only the receivers and the emitters
  }
  return workers_->run([t0, on_receivers, emitters, receivers, rays = shadow_scene_,
                                         scene = scene_, poses = poses_, cache = cache_] {
    ReceiverShadows out{on_receivers ? receivers : Mesh{}, emitters, {}, {}, {}, t0};
    const auto& objects = scene->objects;
    if (on_receivers) {
      out.lines = std::make_shared<LineShadows>(
          cache ? cached_shadow_lines(receivers.positions, receivers.normals, *emitters, rays->proxy(), scene->room)
                : build_shadow_lines(receivers.positions, receivers.normals, *emitters, rays->proxy()));
      for (std::size_t i = 0; i < objects.size(); ++i) out.lines->add_object(objects[i].model, poses[i]);
      out.bounce =
          std::make_shared<ObjectBounce>(out.lines->lines().origins, receivers.normals, out.lines->lines().unshadowed);
      for (std::size_t i = 0; i < objects.size(); ++i) {
        out.bounce->add_object(objects[i].model, objects[i].albedo, poses[i]);
        out.bounce->set_object_enabled(int(i), objects[i].bounce);
      }
    }
    if (objects.size() >= 2) {
      out.object_shadows = std::make_shared<ObjectShadows>(*emitters);
      for (std::size_t i = 0; i < objects.size(); ++i) out.object_shadows->add_object(objects[i].model, poses[i]);
    }
    return out;
  });
}

void Compositor::take_shadows(ReceiverShadows built) {
  if (built.lines) {
    shadows_ = std::move(built.lines);
    bounce_ = std::move(built.bounce);
    renderer_->set_receivers(built.receivers);
    give_bounce_occlusion();
    spdlog::debug("shadows: {} receivers, {} emitter patches, {} lines, built in {:.0f} ms",
                  built.receivers.positions.size(), built.emitters->patches.size(), shadows_->lines().lines.size(),
                  std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - built.started).count());
  }
  if (built.object_shadows) {
    object_shadows_ = std::move(built.object_shadows);
    spdlog::debug("objects shadow each other: {} objects, {} emitter samples", object_shadows_->object_count(),
                  built.emitters->samples.size());
  }
}

void Compositor::set_shadow_quality(const ShadowQuality& quality) {
  if (quality == shadow_quality_) return;
  check(quality);
  const bool same_lines = quality.emitter_patches == shadow_quality_.emitter_patches &&
                          quality.lines_per_patch == shadow_quality_.lines_per_patch;
  shadow_quality_ = quality;
  if (same_lines) return;  // only when the contact receivers are built changed: from the next prepare()
  contact_build_ = {};  // its lines are to the old emitters: dropped when done
  shadows_.reset();
  sphere_shadows_.reset();
  object_shadows_.reset();
  bounce_.reset();
  contact_.reset();
  contact_uploaded_ = false;
  std::future<ReceiverShadows> shadows = start_shadows(renderer_->features());
  take_shadows(workers_->get(shadows));
  relight_shadows();
  shadows_uploaded_ = object_shadows_uploaded_ = false;
}

void Compositor::set_object_pose(std::size_t index, const glm::dmat4& T_world_model) {
  move_object(index, T_world_model);
  renderer_->set_object_pose(int(index), T_world_model);
}

void Compositor::move_object(std::size_t index, const glm::dmat4& T_world_model) {
  if (poses_.at(index) == T_world_model) return;
  poses_[index] = T_world_model;
  frames_at_rest_ = 0;
  pose_object_points();
  vertex_light_stale_[index] = 1;
  lights_blocked_stale_[index] = 1;
  if (shadows_) shadows_->set_object_pose(int(index), T_world_model);
  if (object_shadows_) object_shadows_->set_object_pose(int(index), T_world_model);
  if (bounce_) bounce_->set_object_pose(int(index), T_world_model);
}

void Compositor::set_lighting(const SceneLighting& lighting) {
  if (static_cast<bool>(lighting.volume) != static_cast<bool>(volume_))
    throw RuntimeError("compositor: relit lighting must keep the scene's lighting method");
  volume_ = lighting.volume;
  sh_ = lighting.sh;
  renderer_->set_irradiance_volume(volume_.get());
  for (std::size_t i = 0; i < scene_->objects.size(); ++i) renderer_->set_object_material(int(i), albedo_.at(i), sh_);
  light_scale_ = lighting.scale;
  std::fill(vertex_light_stale_.begin(), vertex_light_stale_.end(), 1);
  std::fill(lights_blocked_stale_.begin(), lights_blocked_stale_.end(), 1);
  relight_shadows();
}

// The shadow lines' emitters scaled by the room's change (set_lighting), each sample by
// the cell its direction from the map's capture point falls in.
void Compositor::relight_shadows() {
  if (!shadows_ || light_scale_.rgb.size() <= 1) return;
  const std::vector<glm::vec3> sample_scale = emitter_sample_scale();
  shadows_->relight(sample_scale);
  if (bounce_) bounce_->relight(shadows_->lines().unshadowed);
  shadows_uploaded_ = false;
  if (contact_ && contact_->lines) {
    contact_->lines->relight(sample_scale);
    correct_contact_shadows();
  }
}

std::vector<glm::vec3> Compositor::emitter_sample_scale() const {
  const ShadowLines& lines = shadows_->lines();
  const EnvironmentMap& map = scene_->map;
  std::vector<glm::vec3> sample_scale;
  sample_scale.reserve(lines.samples.size());
  for (const EmitterPoint& e : lines.samples)  // distant: the position is the direction
    sample_scale.push_back(light_scale_.at(
        map.map_direction(lines.distant ? glm::dvec3(e.position) : glm::dvec3(e.position) - map.capture_position)));
  return sample_scale;
}

// The contact receivers of objects at `poses`, their lines traced and blocked (not relit:
// the room's change is applied when they are taken, as it may change meanwhile). Runs on
// a worker thread: everything it reads is its own or immutable.
std::shared_ptr<Compositor::ContactShadows> Compositor::build_contact_shadows(
    std::shared_ptr<const ShadowScene> shadow_scene, Mesh coarse, std::shared_ptr<const Emitters> emitters,
    std::shared_ptr<const LoadedScene> scene, std::vector<glm::dmat4> poses, bool cache) {
  const auto t0 = std::chrono::steady_clock::now();
  auto built = std::make_shared<ContactShadows>();
  std::vector<const Mesh*> models;
  for (const LoadedObject& o : scene->objects) models.push_back(&o.model);
  const ContactSettings settings;
  built->patch =
      build_contact_patch(shadow_scene->proxy(), coarse,
                          contact_regions(shadow_scene->receiver_regions(), models, poses, settings.reach), settings);
  if (!built->patch.empty()) {
    const Mesh& patch = built->patch.receivers;
    built->lines = std::make_unique<LineShadows>(
        cache ? cached_shadow_lines(patch.positions, patch.normals, *emitters, shadow_scene->proxy(), scene->room)
              : build_shadow_lines(patch.positions, patch.normals, *emitters, shadow_scene->proxy()));
    for (std::size_t i = 0; i < poses.size(); ++i) built->lines->add_object(scene->objects[i].model, poses[i]);
    built->lines->update();
    spdlog::debug("contact shadows: {} receivers, {} lines, built in {:.0f} ms", patch.positions.size(),
                  built->lines->lines().lines.size(),
                  std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  built->drawn = built->patch;
  built->drawn_poses = poses;
  built->poses = std::move(poses);
  return built;
}

bool Compositor::contact_wanted(const gl::CompositeFeatures& features) const {
  return emitters_ && shadows_enabled_ && features.lines && features.contact;
}

bool Compositor::contact_due() const {
  return shadow_quality_.contact_while_moving || frames_at_rest_ >= kRestFrames;
}

// Starts the contact build for the objects' poses now, when they are wanted, at rest and
// not built or under way. A build for poses that are no longer the objects' is waited
// for first (one worker at a time).
void Compositor::start_contact_build(const gl::CompositeFeatures& features) {
  if (!contact_wanted(features) || !contact_due() || (contact_ && contact_->poses == poses_)) return;
  if (contact_build_.valid() && contact_build_poses_ == poses_) return;
  contact_build_poses_ = poses_;
  contact_build_ = workers_->run([rays = shadow_scene_, coarse = receivers_, emitters = emitters_, scene = scene_,
                                  poses = poses_, cache = cache_] {
    return build_contact_shadows(rays, coarse, emitters, scene, poses, cache);
  });
}

// The build under way, when it is for the objects' poses (waiting for it), relit to the
// room's light and with its correction of the coarse shadow; one for other poses is
// dropped once it is done.
void Compositor::take_contact_build() {
  if (!contact_build_.valid()) return;
  if (contact_build_poses_ != poses_) {
    contact_build_ = {};  // for a pose the objects left: its result is dropped when done
    return;
  }
  contact_ = workers_->get(contact_build_);
  if (contact_->lines && light_scale_.rgb.size() > 1) contact_->lines->relight(emitter_sample_scale());
  correct_contact_shadows();
}

// What the contact receivers draw over the coarse shadow where they lie now: where they
// were built, their attenuation divided by the coarse one; carried, that blended with
// the correction they had where they were built (carried_correction).
void Compositor::correct_contact_shadows() {
  if (contact_->lines) {
    contact_->correction = contact_->drawn.correction(contact_->lines->attenuation(), shadows_->attenuation());
    if (contact_->drawn_poses == contact_->poses)
      contact_->built_correction = contact_->correction;
    else
      contact_->correction = carried_correction(contact_->correction, contact_->built_correction);
  }
  contact_uploaded_ = false;
}

// Carries the contact receivers with the objects that moved, builds them again once the
// objects have stood still long enough, and hands the renderer what changed.
void Compositor::update_contact_shadows(FrameLight& light, bool coarse_changed) {
  const bool wanted = contact_wanted(renderer_->features());
  if (wanted && contact_due()) start_contact_build(renderer_->features());
  take_contact_build();
  if (contact_ && contact_->drawn_poses != poses_) {
    std::vector<glm::dmat4> moved;
    for (std::size_t i = 0; i < poses_.size(); ++i) moved.push_back(poses_[i] * glm::inverse(contact_->poses[i]));
    contact_->drawn = contact_->patch.carried(moved, receivers_);
    contact_->drawn_poses = poses_;
    correct_contact_shadows();
  } else if (contact_ && coarse_changed) {
    correct_contact_shadows();
  }
  contact_pending_ = wanted && (!contact_ || contact_->poses != poses_);
  if (contact_uploaded_) return;
  if (wanted && contact_ && contact_->lines)
    light.contact = FrameLight::Contact{contact_->drawn.receivers, contact_->correction};
  else
    light.contact = FrameLight::Contact{};
  contact_uploaded_ = true;
}

void Compositor::set_object_shading(ObjectShading shading) {
  if (shading == shading_) return;
  shading_ = shading;
  if (shading == ObjectShading::PerPixel)
    for (std::size_t i = 0; i < scene_->objects.size(); ++i) renderer_->set_object_vertex_irradiance(int(i), {});
  std::fill(vertex_light_stale_.begin(), vertex_light_stale_.end(), 1);
}

// With self-occlusion on, the stale objects' shadows on themselves from the exact lights.
void Compositor::shadow_objects_themselves(FrameLight& light) {
  light.lights_blocked.assign(scene_->objects.size(), std::nullopt);
  if (!renderer_->features().self_occlusion || light_self_shadow_.empty() || !volume_) return;
  for (std::size_t i = 0; i < scene_->objects.size(); ++i) {
    if (!lights_blocked_stale_[i]) continue;
    lights_blocked_[i] = light_self_shadow_[i]->blocked(poses_[i], volume_->lights, volume_->capture_position);
    light.lights_blocked[i] = lights_blocked_[i];
    lights_blocked_stale_[i] = 0;
  }
}

// Per-vertex shading: the stale objects' light from the volume, with their self-occlusion when it is on.
void Compositor::light_vertices(FrameLight& light) {
  light.vertex_irradiance.assign(scene_->objects.size(), std::nullopt);
  if (shading_ != ObjectShading::PerVertex || !volume_) return;
  const bool occluded = renderer_->features().self_occlusion && !self_occlusion_.empty();
  for (std::size_t i = 0; i < scene_->objects.size(); ++i) {
    if (!vertex_light_stale_[i]) continue;
    const std::span<const VertexOcclusion> occlusion =
        occluded ? std::span<const VertexOcclusion>(self_occlusion_[i]) : std::span<const VertexOcclusion>();
    const std::span<const float> blocked =
        occluded && !light_self_shadow_.empty() ? std::span<const float>(lights_blocked_[i]) : std::span<const float>();
    light.vertex_irradiance[i] = vertex_irradiance(scene_->objects[i].model, poses_[i], occlusion, blocked, *volume_);
    vertex_light_stale_[i] = 0;
  }
}

void Compositor::set_object_bounce(std::size_t index, bool on) {
  if (index >= poses_.size()) throw RuntimeError("compositor: no object " + std::to_string(index));
  if (bounce_) bounce_->set_object_enabled(int(index), on);
}

void Compositor::set_object_albedo(std::size_t index, const glm::vec3& albedo) {
  albedo_.at(index) = albedo;
  renderer_->set_object_material(int(index), albedo, sh_);
  if (bounce_) bounce_->set_object_albedo(int(index), albedo);
}

// The light the objects reflect onto each other (with two or more), per object, or none.
std::vector<std::vector<glm::vec3>> Compositor::object_bounce(bool on) const {
  std::vector<std::vector<glm::vec3>> out;
  if (!bounce_ || scene_->objects.size() < 2) return out;
  for (std::size_t i = 0; i < scene_->objects.size(); ++i) {
    const std::vector<glm::vec3>& received = bounce_->object_bounce(int(i));
    out.push_back(on ? received : std::vector<glm::vec3>(received.size(), glm::vec3(0.0f)));
  }
  return out;
}

void Compositor::set_shadows_enabled(bool on, bool on_each_other) {
  if (on != shadows_enabled_) {
    shadows_enabled_ = on;
    shadows_uploaded_ = contact_uploaded_ = false;
    if (shadows_ && !on) {
      renderer_->set_receiver_attenuation(std::vector<glm::vec3>(shadows_->attenuation().size(), glm::vec3(1.0f)));
      const auto none = object_bounce(false);
      for (std::size_t i = 0; i < none.size(); ++i) renderer_->set_object_bounce_light(int(i), none[i]);
    }
  }
  if (on_each_other != object_shadows_enabled_) {
    object_shadows_enabled_ = on_each_other;
    object_shadows_uploaded_ = false;
    if (object_shadows_ && !on_each_other)
      for (std::size_t i = 0; i < object_shadows_->object_count(); ++i)
        renderer_->set_object_light_attenuation(
            int(i), std::vector<glm::vec3>(object_shadows_->vertex_attenuation(int(i)).size(), glm::vec3(1.0f)));
  }
}

cv::Mat Compositor::composite(const cv::Mat& video_bgr8, const std::optional<Pose>& T_world_camera, double exposure,
                              gl::OverlayTimings* timings) {
  return render(prepare(), video_bgr8, T_world_camera, exposure, timings);
}

FrameLight Compositor::prepare() {
  FrameLight light;
  light.poses = poses_;
  const auto t0 = std::chrono::steady_clock::now();
  // The lines, the bounce and the objects' shadows on each other do not share state: they
  // run side by side (and the bounce over the receivers within).
  const bool lines = shadows_ && shadows_enabled_, bounce = lines && bounce_ && renderer_->features().bounce;
  const bool spheres = lines && !renderer_->features().lines;
  const bool on_each_other = object_shadows_ && object_shadows_enabled_;
  bool lines_changed = false, bounce_changed = false, others_changed = false;
  {
    tbb::task_group group;
    if (bounce) group.run([&] { bounce_changed = bounce_->update(object_irradiance(volume_.get(), sh_)); });
    if (on_each_other) group.run([&] { others_changed = object_shadows_->update(); });
    group.run_and_wait([&] {
      if (lines) lines_changed = spheres ? update_sphere_shadows() : shadows_->update();
    });
  }
  if (lines && (lines_changed || bounce_changed || !shadows_uploaded_)) {
    const std::vector<glm::vec3>& shadow = spheres ? sphere_shadows_->attenuation : shadows_->attenuation();
    light.receiver_attenuation = bounce ? with_bounce(shadow, *bounce_) : shadow;
    light.object_bounce = object_bounce(bounce);
    shadows_uploaded_ = true;
  }
  if (on_each_other && (others_changed || !object_shadows_uploaded_)) {
    for (std::size_t i = 0; i < object_shadows_->object_count(); ++i)
      light.object_shadowing.push_back(object_shadows_->vertex_attenuation(int(i)));
    object_shadows_uploaded_ = true;
  }
  update_contact_shadows(light, lines_changed && !spheres);
  if (frames_at_rest_ < kRestFrames && ++frames_at_rest_ == kRestFrames)
    start_contact_build(renderer_->features());  // for the next frame
  shadow_objects_themselves(light);
  const auto t1 = std::chrono::steady_clock::now();
  light_vertices(light);
  light.shadows_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  light.vertex_light_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
  return light;
}

bool Compositor::update_sphere_shadows() {
  if (!sphere_shadows_) {
    auto built = std::make_shared<SphereShadows>();
    built->receivers = shadow_scene().receivers();
    built->emitters = shadow_scene().emitters(built->receivers.positions, built->receivers.normals,
                                              sphere_baseline_emitter_options());
    sphere_shadows_ = std::move(built);
  }
  SphereShadows& s = *sphere_shadows_;
  if (s.poses == poses_) return false;
  std::vector<BoundingSphere> spheres;
  for (std::size_t i = 0; i < poses_.size(); ++i)
    spheres.push_back(bounding_sphere(scene_->objects[i].model, poses_[i]));
  s.attenuation =
      sphere_attenuation(s.receivers.positions, s.receivers.normals, s.emitters, shadow_scene().proxy(), spheres);
  s.poses = poses_;
  return true;
}

void Compositor::forget_prepared() {
  shadows_uploaded_ = object_shadows_uploaded_ = contact_uploaded_ = false;
  std::fill(vertex_light_stale_.begin(), vertex_light_stale_.end(), 1);
  std::fill(lights_blocked_stale_.begin(), lights_blocked_stale_.end(), 1);
}

cv::Mat Compositor::render(const FrameLight& light, const cv::Mat& video_bgr8,
                           const std::optional<Pose>& T_world_camera, double exposure, gl::OverlayTimings* timings,
                           std::span<const gl::ShutterInstant> shutter) {
  for (std::size_t i = 0; i < light.poses.size(); ++i) renderer_->set_object_pose(int(i), light.poses[i]);
  if (light.receiver_attenuation) renderer_->set_receiver_attenuation(*light.receiver_attenuation);
  if (light.contact) renderer_->set_contact_receivers(light.contact->receivers, light.contact->correction);
  for (std::size_t i = 0; i < light.object_bounce.size(); ++i)
    renderer_->set_object_bounce_light(int(i), light.object_bounce[i]);
  for (std::size_t i = 0; i < light.object_shadowing.size(); ++i)
    renderer_->set_object_light_attenuation(int(i), light.object_shadowing[i]);
  for (std::size_t i = 0; i < light.vertex_irradiance.size(); ++i)
    if (light.vertex_irradiance[i]) renderer_->set_object_vertex_irradiance(int(i), *light.vertex_irradiance[i]);
  for (std::size_t i = 0; i < light.lights_blocked.size(); ++i)
    if (light.lights_blocked[i]) renderer_->set_object_lights_blocked(int(i), *light.lights_blocked[i]);
  if (timings) {
    *timings = {};
    timings->shadows_ms = light.shadows_ms;
    timings->vertex_light_ms = light.vertex_light_ms;
  }
  return renderer_->render_overlay(video_bgr8, T_world_camera, exposure, timings, shutter);
}

}  // namespace lumar
