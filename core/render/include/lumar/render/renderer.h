#pragma once
// The OpenGL compositor: undistorted video as background, the proxy room as an
// occluder (depth only), virtual diffuse objects lit by order-2 SH irradiance, all
// composited in linear light and encoded to sRGB 8-bit. Also renders the proxy room's
// projected radiance (for synthesis) and per-pixel world positions (for tests).
//
// Create, use and destroy a Renderer while the same gl::Context is current.
// Images are OpenCV-shaped: top row first, BGR channel order.
#include <array>
#include <glm/glm.hpp>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <vector>

#include "lumar/base/camera.h"
#include "lumar/base/pose.h"
#include "lumar/lighting/self_occlusion.h"
#include "lumar/lighting/sh.h"
#include "lumar/scene/envmap.h"
#include "lumar/scene/mesh.h"

namespace lumar {
class IrradianceVolume;
}

namespace lumar::gl {

// Wall time of each stage of render_overlay. Asking for timings makes the stages wait
// for each other (glFinish between them), so ask only when profiling.
struct OverlayTimings {
  double shadows_ms = 0;       // the compositor's: moved objects' shadows traced again (shadow lines)
  double vertex_light_ms = 0;  // the compositor's: moved objects' light per vertex (ObjectShading::PerVertex)
  double upload_ms = 0, background_ms = 0, depth_ms = 0, objects_ms = 0, antialiasing_ms = 0, motion_blur_ms = 0,
         blur_ms = 0, readback_ms = 0;
};

// How the camera turned light into video, so that rendered pixels look like the
// camera's: its response (8-bit code -> linear value) and its radial vignetting.
struct VideoRadiometry {
  // linear_of_code[channel][code], channels B, G, R (OpenCV order), non-decreasing.
  // Empty: the default sRGB curve.
  std::vector<std::array<float, 256>> linear_of_code;
  // Gain 1 + a r^2 + b r^4, r = distance from the principal point over the half-diagonal,
  // in the pixels of `video_camera` (the distorted camera the undistortion map samples).
  // Without an undistortion map or a valid video_camera: the output camera's pixels.
  double vignetting_a = 0.0, vignetting_b = 0.0;
  CameraIntrinsics video_camera;
  // The sensor's noise per channel (B, G, R) in the response's linear units: variance
  // read_variance + shot_gain * linear (calib/sensor_noise.h estimates it from video).
  std::array<float, 3> noise_read_variance{}, noise_shot_gain{};
  // The camera's blur before its clipping (lens, sensor) as a Gaussian, output pixels.
  // The undistortion's resampling, which follows the clipping, is applied apart, where
  // the renderer has an undistortion map (CompositeFeatures::blur).
  double blur_sigma_px = 0.0;
  // How many pixels share one chroma sample in the camera's or codec's YCbCr, along x and
  // y (1 or 2 each): 2×2 for 4:2:0 (JPEG, H.264), 2×1 for 4:2:2 (YUYV), 1×1 for none.
  int chroma_horizontal = 1, chroma_vertical = 1;
};

// What makes rendered pixels look like the camera's own around them (docs/ground_truth.md,
// "What closes the gap"); each can be switched off to measure what it brings.
struct CompositeFeatures {
  bool antialiasing = true;    // the objects' coverage of outline pixels, from 4 samples (MSAA)
  bool self_occlusion = true;  // the objects' baked occlusion of themselves
  bool noise = true;           // VideoRadiometry's noise on rendered pixels
  bool blur = true;            // VideoRadiometry's blur, and the undistortion's resampling, on rendered pixels
  bool chroma = true;          // VideoRadiometry's chroma subsampling on rendered pixels and their edges
  bool bounce = true;          // the objects' light reflected onto the receivers (the Compositor's)
  // The objects' shadows on the room from the radiosity lines (the Compositor's); off:
  // the 2004 system's, one line per bright patch against each object's bounding sphere.
  bool lines = true;
  // With the lines: a dense patch of receivers where an object rests on a receiver
  // surface, for the contact shadow the lines' coarse receivers blur (the Compositor's).
  bool contact = true;
  // The objects drawn at several instants of the shutter and averaged, when the frame
  // gives them (render_overlay's `shutter`): their motion blur against the camera.
  bool motion_blur = true;

  // Every feature off: the 2004 system's look, the measuring baseline.
  static constexpr CompositeFeatures none() { return {false, false, false, false, false, false, false, false, false}; }
};

// One instant while the camera's shutter was open: where the camera and each object
// (add_object order) were then.
struct ShutterInstant {
  Pose T_world_camera;
  std::vector<glm::dmat4> T_world_model;
};

class Renderer {
 public:
  // `camera` is the undistorted output camera (its distortion is ignored); output
  // images are camera.width x camera.height. Throws InputError for an invalid camera.
  explicit Renderer(const CameraIntrinsics& camera);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Proxy room in world coordinates (metres). An empty mesh means no occluder.
  void set_room(const Mesh& room_world);
  // Radiance map projected onto the room by render_room_radiance.
  void set_environment(const EnvironmentMap& map);
  // A virtual object in model units; returns its id. Its pose starts as identity, its
  // material as albedo 0.8 under no light.
  int add_object(const Mesh& mesh_model);
  void set_object_pose(int id, const glm::dmat4& T_world_model);
  void set_object_material(int id, const glm::vec3& albedo, const SH9& irradiance_sh);
  // Per vertex (mesh order), the share of the light the object still gets when the
  // other objects block some of it (object_shadows.h): multiplies its irradiance.
  // 1 until set; throws InputError unless there is one value per vertex.
  void set_object_light_attenuation(int id, std::span<const glm::vec3> attenuation);
  // Per vertex (mesh order): the irradiance the other objects reflect onto it, added to
  // its shading (lighting/shadows/object_bounce.h). Unset: none.
  void set_object_bounce_light(int id, std::span<const glm::vec3> irradiance);
  // Per vertex (mesh order): the object's light, E(bent normal) x open share
  // (lighting/vertex_irradiance.h), which then shades it instead of the volume or SH9 per
  // pixel; the other objects' shadows and bounce still apply. Empty: back to per pixel.
  // Throws InputError unless empty or one value per vertex.
  void set_object_vertex_irradiance(int id, std::span<const glm::vec3> irradiance);
  // Per vertex (mesh order), the object's occlusion of itself (bake_self_occlusion);
  // unset, the object is open everywhere. Throws InputError unless one value per vertex.
  void set_object_self_occlusion(int id, std::span<const VertexOcclusion> occlusion);
  // Per vertex (mesh order), the share of the volume's exact lights the object blocks
  // itself in its current pose (LightSelfShadow::blocked); shaded with self-occlusion on,
  // it darkens those lights, at the vertex's own normal, instead of the open share.
  // Unset: nothing blocked. Same rules as set_object_light_attenuation.
  void set_object_lights_blocked(int id, std::span<const float> blocked);
  // Shade every object per pixel from this irradiance volume (uploaded as textures;
  // core/irradiance_volume.h) instead of its SH9; nullptr goes back to SH9. A volume of
  // the current one's layout (the same room relit) only updates its light.
  void set_irradiance_volume(const IrradianceVolume* volume);

  // Shadow receivers (world mesh of real surfaces): in render_overlay the video under
  // them is multiplied by their per-vertex attenuation E_with / E_without (1 until set).
  // An empty mesh removes them.
  void set_receivers(const Mesh& receivers_world);
  void set_receiver_attenuation(std::span<const glm::vec3> attenuation);
  // A second, denser receiver mesh where objects touch a receiver surface
  // (lighting/shadows/contact_receivers.h), drawn the same way after the receivers: its
  // per-vertex `correction` multiplies their shadow. An empty mesh removes it.
  void set_contact_receivers(const Mesh& patch_world, std::span<const glm::vec3> correction);

  // Where each output pixel samples the distorted video: cv::initUndistortRectifyMap's
  // map1/map2 as CV_32FC1, output size. Without it the video is drawn unwarped
  // (scaled to the output size).
  void set_undistortion_map(const cv::Mat& map_x, const cv::Mat& map_y);

  // The video's response and vignetting (default: sRGB, no vignetting). Video pixels
  // pass through unchanged; rendered pixels get the vignetting and the response.
  // Throws InputError for a table that is not 3 x 256 finite non-decreasing values.
  void set_video_radiometry(const VideoRadiometry& radiometry);
  // Default: all on. Antialiasing needs the driver's multisampling (4 samples, else what it has).
  void set_features(const CompositeFeatures& features);
  const CompositeFeatures& features() const;
  // The antialiasing's coverage needs only the objects' outlines: each frame it draws each
  // object with the coarsest of its simplified meshes (about half the triangles each)
  // whose surface is within this many output pixels of the mesh's, where the object is
  // nearest the camera. The shading always draws the mesh as given. 0 (the default): the
  // meshes as given. Throws InputError outside [0, kMaxCoverageErrorPx].
  void set_coverage_mesh_error(double pixels);
  double coverage_mesh_error() const;
  // The objects' triangles the last antialiasing pass drew (a frame without the pass, or
  // without a pose, leaves it as it was).
  std::size_t coverage_triangles() const;
  static constexpr double kMaxCoverageErrorPx = 8.0;

  // One composited frame (BGR8, output size). `video_bgr8` is the distorted video frame
  // (CV_8UC3, the undistortion map's source size); `exposure` is the video's linear
  // value per unit of scene radiance. Without a pose (nullopt) the frame shows the
  // undistorted video alone: no object is drawn where the camera cannot be placed.
  // `shutter`: with two instants or more and CompositeFeatures::motion_blur, the frame is
  // drawn at each and the drawings averaged where the objects are at any of them (an
  // accumulation buffer); elsewhere, and without them, it is drawn once at T_world_camera
  // with the poses set. The poses set stay as they were. InputError unless each instant
  // has one pose per object.
  cv::Mat render_overlay(const cv::Mat& video_bgr8, const std::optional<Pose>& T_world_camera, double exposure,
                         OverlayTimings* timings = nullptr, std::span<const ShutterInstant> shutter = {});

  // Linear radiance of the proxy room, textured by projecting the environment map
  // from its capture point, seen by a pinhole `camera` (any size; distortion ignored).
  // CV_32FC3 BGR; pixels that see no room are 0. `map_uv` (optional): where each pixel's
  // radiance comes from in the map, (u, v) / (W, H) in [0, 1] (CV_32FC2), -1 where no room.
  cv::Mat render_room_radiance(const CameraIntrinsics& camera, const Pose& T_world_camera, cv::Mat* map_uv = nullptr);

  // World position of the visible virtual objects after proxy occlusion: CV_32FC4
  // (x, y, z, 1) where covered, (0, 0, 0, 0) elsewhere.
  cv::Mat render_object_world_positions(const Pose& T_world_camera);
  // CV_8UC1, 255 where a virtual object is visible after proxy occlusion.
  cv::Mat render_object_mask(const Pose& T_world_camera);

  // Clip planes used for every view, metres.
  static constexpr double kNear = 0.02, kFar = 200.0;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lumar::gl
