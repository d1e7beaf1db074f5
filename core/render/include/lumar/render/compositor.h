#pragma once
// The overlay for one scene and one camera: proxy room for occlusion, virtual objects
// shaded from the environment map, composited over undistorted video. Set up once,
// then one call per frame. Needs a current OpenGL context (gl/context.h).
#include <future>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/lighting/sh.h"
#include "lumar/render/renderer.h"
#include "lumar/scene/loaded_scene.h"

namespace lumar {

class LineShadows;
class ObjectShadows;
class ObjectBounce;
class IrradianceVolume;
class LightSelfShadow;
class ShadowScene;
struct Emitters;
struct VertexOcclusion;

// The shadows' quality knobs (docs/shadows.md): how many emitter patches the map is split
// into, and how many sample points (line ends) each patch has, so lines per receiver and
// patch.
struct ShadowQuality {
  static constexpr int kMaxLinesPerPatch = 64;  // what the overlay's knob allows
  int emitter_patches = 64;
  int lines_per_patch = 8;
  // The contact receivers (Compositor::contact_shadows) at every pose of a moving object
  // too, a build per frame that moved (about 0.3 s for the walk's two figurines): for
  // offline renders. Else a moving object carries the patch of its last rest with it.
  bool contact_while_moving = false;
  bool operator==(const ShadowQuality&) const = default;
};

// Where the objects' light from the irradiance volume is evaluated: at every covered
// pixel on the GPU, or on the CPU at their vertices (lighting/vertex_irradiance.h), again
// only when an object moved or the light changed, and interpolated across the triangles.
// Per vertex costs a dense mesh little accuracy and llvmpipe most of the objects' stage
// (docs/irradiance.md, "Shading per vertex"). Without a volume (lighting.method "sh9")
// both are the same.
enum class ObjectShading { PerPixel, PerVertex };

// The CPU's part of a frame, worked out by Compositor::prepare without GL: the objects'
// poses, and what of their shadows, bounce and per-vertex light changed since the frame
// before (empty or unset: unchanged). A pipelined replay prepares a frame on another
// thread while the one before is drawn; render() uploads it on the GL thread.
struct FrameLight {
  std::vector<glm::dmat4> poses;                                         // T_world_model per object
  std::optional<std::vector<glm::vec3>> receiver_attenuation;            // shadow and bounce, per receiver
  std::vector<std::vector<glm::vec3>> object_bounce;                     // per object: the others' light on it
  std::vector<std::vector<glm::vec3>> object_shadowing;                  // per object: the others' shadow on it
  std::vector<std::optional<std::vector<glm::vec3>>> vertex_irradiance;  // per object (ObjectShading::PerVertex)
  std::vector<std::optional<std::vector<float>>> lights_blocked;         // per object: its shadow on itself
  // The contact receivers and their correction of the receivers' shadow; an empty mesh
  // removes them (ContactShadows below).
  struct Contact {
    Mesh receivers;
    std::vector<glm::vec3> correction;
  };
  std::optional<Contact> contact;
  double shadows_ms = 0, vertex_light_ms = 0;
};

// What a compositor starts with. Each can change later (Compositor::set_features,
// set_shadow_quality), at the cost of the work that redoes; given here, the shadows are
// built once, and what is switched off is never built.
struct CompositorSettings {
  // Load the irradiance volume and the shadow lines (the contact receivers' too) from the
  // disk cache, and store them there once built (lighting/irradiance_volume.h,
  // lighting/shadows/shadow_line_cache.h); false: build them every time.
  bool cache = true;
  gl::CompositeFeatures features;  // all on
  ShadowQuality shadows;
};

class Compositor {
 public:
  // `output_camera`: the undistorted camera the renderer draws with. `map_x`, `map_y`:
  // for each output pixel, where to sample the distorted video (may be empty when the
  // video is already undistorted).
  Compositor(std::shared_ptr<const LoadedScene> scene, const CameraIntrinsics& output_camera, const cv::Mat& map_x,
             const cv::Mat& map_y, const CompositorSettings& settings = {});
  ~Compositor();

  // Composites one BGR8 video frame seen from T_world_camera (nullopt: no pose, the
  // undistorted video alone); `exposure` is the video's linear value per unit of scene radiance.
  // It is render(prepare(), ...). `shutter`: the camera and the objects at instants of
  // the shutter, for their motion blur (gl::Renderer::render_overlay).
  cv::Mat composite(const cv::Mat& video_bgr8, const std::optional<Pose>& T_world_camera, double exposure,
                    gl::OverlayTimings* timings = nullptr);
  // The two halves of composite(). prepare() touches no GL and may run on another thread
  // than render(), one frame or two ahead, provided nothing else changes this compositor
  // meanwhile; the frames must be rendered in the order they were prepared.
  FrameLight prepare();
  cv::Mat render(const FrameLight& light, const cv::Mat& video_bgr8, const std::optional<Pose>& T_world_camera,
                 double exposure, gl::OverlayTimings* timings = nullptr,
                 std::span<const gl::ShutterInstant> shutter = {});
  // Frames were prepared and never rendered (a pipelined run stopped): the next prepare()
  // hands on everything again, not only what changed since.
  void forget_prepared();

  // Moves object `index` (manifest order): the renderer and the shadow lines follow; the
  // shadows are recomputed in the next composite() only if a pose changed.
  void set_object_pose(std::size_t index, const glm::dmat4& T_world_model);
  // The same for prepare() alone: the renderer takes the pose from the next FrameLight
  // it renders (no GL here).
  void move_object(std::size_t index, const glm::dmat4& T_world_model);
  const glm::dmat4& object_pose(std::size_t index) const { return poses_.at(index); }
  // The object's diffuse albedo: its shading and the light it reflects onto the room.
  void set_object_albedo(std::size_t index, const glm::vec3& albedo);
  // Whether the object reflects light onto the receivers (the manifest's "bounce").
  void set_object_bounce(std::size_t index, bool on);
  // Soft shadows of the objects on the receivers and, with two objects or more, on each
  // other (docs/shadows.md); on by default. `on_each_other`: the latter alone.
  void set_shadows_enabled(bool on, bool on_each_other);
  void set_shadows_enabled(bool on) { set_shadows_enabled(on, on); }
  bool shadows_enabled() const { return shadows_enabled_; }
  bool object_shadows_enabled() const { return object_shadows_enabled_; }
  // Rebuilds the shadow lines and the objects' shadows on each other with these knobs;
  // the objects keep their current poses.
  void set_shadow_quality(const ShadowQuality& quality);
  const ShadowQuality& shadow_quality() const { return shadow_quality_; }
  // Antialiasing, self-occlusion, noise, blur and bounce (gl::CompositeFeatures); all on
  // by default. The objects' self-occlusion is baked the first time it is on. Bounce is
  // the light the objects reflect onto the receivers, added to their shadows, and onto
  // each other, added to their shading (lighting/shadows/object_bounce.h), from objects
  // whose manifest entry allows it.
  void set_features(const gl::CompositeFeatures& features);
  void set_object_shading(ObjectShading shading);
  ObjectShading object_shading() const { return shading_; }
  // The shadow lines, or nullptr when the scene has no receivers.
  const LineShadows* shadows() const { return shadows_.get(); }
  // The objects' shadows on each other, or nullptr with fewer than two objects.
  const ObjectShadows* object_shadows() const { return object_shadows_.get(); }
  // The objects' light on the receivers, or nullptr when the scene has no receivers.
  const ObjectBounce* bounce() const { return bounce_.get(); }
  // The contact receivers' lines (lighting/shadows/contact_receivers.h) for the poses
  // they were built at, or nullptr while there are none. They are built once the objects
  // have stood still for kRestFrames prepared frames (at once for objects that never
  // move); in between, an object that slides or turns along the surface it stands on
  // carries its part of the patch with it (contact_receivers() below), and one that
  // leaves the surface loses it. ShadowQuality::contact_while_moving builds them at every
  // pose instead. The build runs on a worker thread from the moment it can start (for
  // objects that never move, while the coarse shadows are still loading), and the
  // prepare() that first shows it waits for it; a build for poses the objects have left
  // is dropped: the frames a build appears in do not depend on the machine's speed.
  static constexpr int kRestFrames = 3;
  const LineShadows* contact_shadows() const;
  // The contact receivers where they are drawn now (carried with the objects), or nullptr
  // when none are drawn.
  const Mesh* contact_receivers() const;
  // True while contact receivers are wanted but not built for the poses yet: preparing the same frame
  // again brings them nearer, so a paused window keeps compositing until it is false.
  bool settling() const { return contact_pending_; }

  // The room's light changed (pipeline/live_lighting.h): shade the objects from this
  // lighting (relit_scene_lighting, or a blend of two), and scale the shadow lines'
  // emitters by its change per map cell, so a lamp that went out takes its shadows with
  // it; the light the objects reflect follows. The renderer's environment map stays the
  // captured one, the reference the changes are measured against. The objects' shadows
  // on each other keep the captured map's emitters.
  void set_lighting(const SceneLighting& lighting);

  gl::Renderer& renderer() { return *renderer_; }
  const LoadedScene& scene() const { return *scene_; }
  const std::shared_ptr<const LoadedScene>& shared_scene() const { return scene_; }
  const CameraIntrinsics& output_camera() const { return camera_; }
  const SH9& lighting_sh() const { return sh_; }
  // The irradiance volume that shades the objects per pixel (built for the scene's
  // movement box, or loaded from the cache), or nullptr when lighting.method is "sh9".
  const std::shared_ptr<const IrradianceVolume>& irradiance_volume() const { return volume_; }
  // A few hundred surface points of the virtual objects in their current poses, world
  // coordinates, for checking where they project.
  const std::vector<glm::dvec3>& object_points() const { return object_points_; }

 private:
  CameraIntrinsics camera_;
  std::shared_ptr<const LoadedScene> scene_;
  SH9 sh_;
  std::unique_ptr<gl::Renderer> renderer_;
  std::shared_ptr<const IrradianceVolume> volume_;  // shared_ptr: incomplete here
  // The scene's proxy as rays, built at its first use and shared by every shadow method.
  std::shared_ptr<const ShadowScene> shadow_scene_;  // shared_ptr: incomplete here
  const ShadowScene& shadow_scene();
  struct ReceiverShadows;
  std::future<ReceiverShadows> start_shadows(const gl::CompositeFeatures& features);
  void take_shadows(ReceiverShadows built);
  bool cache_ = true;  // the volume and the shadow lines from the disk cache
  struct Workers;
  std::unique_ptr<Workers> workers_;  // waits for its tasks as it goes
  void bake_self_occlusion_once();
  void give_bounce_occlusion();
  std::vector<std::vector<VertexOcclusion>> self_occlusion_;  // per object, once baked
  // Per object, with self-occlusion on: its shadow on itself from the volume's exact
  // lights, for its current pose (again when it moves or the room is relit).
  std::vector<std::shared_ptr<const LightSelfShadow>> light_self_shadow_;  // built with the bake
  std::vector<std::vector<float>> lights_blocked_;
  std::vector<char> lights_blocked_stale_;
  void shadow_objects_themselves(FrameLight& light);
  std::vector<glm::dmat4> poses_;                        // T_world_model per object
  std::vector<glm::vec3> albedo_;                        // per object
  std::vector<std::vector<glm::dvec3>> sampled_points_;  // per object, model coordinates
  std::vector<glm::dvec3> object_points_;                // the above, posed
  void pose_object_points();
  std::shared_ptr<LineShadows> shadows_;  // shared_ptr: LineShadows is incomplete here
  // With CompositeFeatures::lines off: the 2004 baseline's shadows on the same receivers,
  // built at their first use, traced again whenever an object moved.
  struct SphereShadows;
  std::shared_ptr<SphereShadows> sphere_shadows_;
  bool update_sphere_shadows();
  std::shared_ptr<ObjectShadows> object_shadows_;
  Mesh receivers_;                            // the lines' receivers
  std::shared_ptr<const Emitters> emitters_;  // the lines' emitters
  struct ContactShadows;
  std::shared_ptr<ContactShadows> contact_;
  // The build under way on a worker, and the poses it is for.
  std::future<std::shared_ptr<ContactShadows>> contact_build_;
  std::vector<glm::dmat4> contact_build_poses_;
  int frames_at_rest_ = kRestFrames;  // prepared frames since an object last moved
  bool contact_uploaded_ = false;
  bool contact_pending_ = false;
  static std::shared_ptr<ContactShadows> build_contact_shadows(std::shared_ptr<const ShadowScene> shadow_scene,
                                                               Mesh coarse, std::shared_ptr<const Emitters> emitters,
                                                               std::shared_ptr<const LoadedScene> scene,
                                                               std::vector<glm::dmat4> poses, bool cache);
  bool contact_wanted(const gl::CompositeFeatures& features) const;
  bool contact_due() const;  // the objects at rest long enough, or contact_while_moving
  void start_contact_build(const gl::CompositeFeatures& features);
  void take_contact_build();
  void update_contact_shadows(FrameLight& light, bool coarse_changed);
  void correct_contact_shadows();
  std::vector<glm::vec3> emitter_sample_scale() const;
  std::shared_ptr<ObjectBounce> bounce_;
  ShadowQuality shadow_quality_;
  MapCellScale light_scale_;  // the room's change since the map was captured (set_lighting)
  void relight_shadows();
  std::vector<std::vector<glm::vec3>> object_bounce(bool on) const;
  ObjectShading shading_ = ObjectShading::PerPixel;
  std::vector<char> vertex_light_stale_;  // per object: moved, or the light changed, since lit
  void light_vertices(FrameLight& light);
  bool shadows_enabled_ = true, object_shadows_enabled_ = true, shadows_uploaded_ = false,
       object_shadows_uploaded_ = false;
};

}  // namespace lumar
