#include "lumar/pipeline/overlay.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>

#include <spdlog/spdlog.h>

#include <opencv2/core.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/camera_blur.h"
#include "lumar/calib/sensor_noise.h"
#include "lumar/lighting/irradiance_volume.h"

namespace lumar::pipeline {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

gl::VideoRadiometry renderer_radiometry(const capture::Radiometry& radiometry, const CameraIntrinsics& camera,
                                        const std::optional<calib::CameraResponse>& response) {
  gl::VideoRadiometry out;
  out.video_camera = camera;
  out.vignetting_a = radiometry.vignetting_a;
  out.vignetting_b = radiometry.vignetting_b;
  if (response) out.linear_of_code.assign(response->exposure.begin(), response->exposure.end());
  return out;
}

// The scene with the volume's knobs the quality asks for (a copy only when they differ).
std::shared_ptr<const LoadedScene> with_volume_knobs(std::shared_ptr<const LoadedScene> scene,
                                                     const OverlayQuality& q) {
  const LightingSettings& lighting = scene->manifest.lighting;
  const bool lights = q.exact_lights && lighting.max_lights != q.exact_lights;
  const bool map = q.shadow_map && lighting.shadow_map_resolution != q.shadow_map;
  if (!lights && !map) return scene;
  auto copy = std::make_shared<LoadedScene>(*scene);
  if (lights) copy->manifest.lighting.max_lights = q.exact_lights;
  if (map) copy->manifest.lighting.shadow_map_resolution = q.shadow_map;
  return copy;
}

void check_quality(const OverlayQuality& q) {
  if (q.exact_lights && (*q.exact_lights < 0 || *q.exact_lights > kMaxExactLights))
    throw InputError(fmt::format("exact lights: {}; use 0 to {}", *q.exact_lights, kMaxExactLights));
  if (q.shadow_map && (*q.shadow_map < kMinShadowMapResolution || *q.shadow_map > kMaxShadowMapResolution))
    throw InputError(fmt::format("shadow maps of {} texels per side; use {} to {}", *q.shadow_map,
                                 kMinShadowMapResolution, kMaxShadowMapResolution));
  if (!(q.coverage_mesh_px >= 0.0 && q.coverage_mesh_px <= gl::Renderer::kMaxCoverageErrorPx))
    throw InputError(fmt::format("coverage meshes within {} px; use 0 (as given) to {}", q.coverage_mesh_px,
                                 gl::Renderer::kMaxCoverageErrorPx));
  if (q.shadows.lines_per_patch < 1 || q.shadows.lines_per_patch > ShadowQuality::kMaxLinesPerPatch)
    throw InputError(fmt::format("{} shadow lines per patch; use 1 to {}", q.shadows.lines_per_patch,
                                 ShadowQuality::kMaxLinesPerPatch));
}
}  // namespace

std::string OverlayQuality::describe() const {
  return fmt::format("{}, {} lines, {} lights, {} shadow maps, {} coverage meshes{}",
                     shading == ObjectShading::PerVertex ? "vertex" : "pixel", shadows.lines_per_patch,
                     exact_lights ? std::to_string(*exact_lights) : "the manifest's",
                     shadow_map ? std::to_string(*shadow_map) + " px" : "the manifest's",
                     coverage_mesh_px > 0 ? fmt::format("{:g} px", coverage_mesh_px) : "exact",
                     shadows.contact_while_moving ? ", contact shadows while moving" : "");
}

Overlay::Overlay(std::shared_ptr<const LoadedScene> scene, const CameraIntrinsics& camera,
                 const capture::Radiometry& radiometry, const std::optional<calib::CameraResponse>& response,
                 const OverlaySettings& settings)
    : exposure_(radiometry.exposure),
      camera_(camera),
      session_radiometry_(radiometry),
      live_(settings.live),
      volume_cache_(settings.volume_cache),
      quality_(settings.quality),
      scene_(scene) {
  check_quality(quality_);
  shutter_s_ = settings.shutter_s.value_or(radiometry.shutter_s);
  if (!(shutter_s_ >= 0.0 && shutter_s_ <= 1.0))
    throw InputError(fmt::format("overlay: a shutter time of {} s; use 0 (no motion blur) to 1 s", shutter_s_));
  shutter_instants_ = settings.shutter_instants;
  if (shutter_instants_ < OverlaySettings::kMinShutterInstants ||
      shutter_instants_ > OverlaySettings::kMaxShutterInstants)
    throw InputError(fmt::format("overlay: {} shutter instants; use {} to {}", shutter_instants_,
                                 OverlaySettings::kMinShutterInstants, OverlaySettings::kMaxShutterInstants));
  if (settings.window) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display)
      throw RuntimeError(
          "overlay: no display to open a window on (DISPLAY is not set); to run headless, leave out --window and "
          "give --out or --frames-dir (the live path too), or run under xvfb-run");
    const int panel = std::max(0, settings.window_panel_width);
    const cv::Size size(camera.width + panel, panel > 0 ? std::max(camera.height, 720) : camera.height);
    auto w = std::make_unique<gl::WindowContext>(size.width, size.height, settings.window_title);
    window_ = w.get();
    context_ = std::move(w);
  } else {
    context_ = gl::create_headless_context();
  }
  maps_ = calib::make_undistortion_maps(camera, settings.undistortion);
  resampling_variance_ = calib::resampling_variance(maps_);
  const calib::UndistortionMaps& maps = maps_;
  compositor_ =
      std::make_unique<Compositor>(with_volume_knobs(std::move(scene), quality_), maps.output, maps.map_x, maps.map_y,
                                   CompositorSettings{settings.volume_cache, settings.features, quality_.shadows});
  // The renderer's linear unit is the response's (sRGB with gain 1 without one).
  response_ = response.value_or(calib::srgb_response(1.0));
  radiometry_ = renderer_radiometry(radiometry, camera, response);
  noise_known_ = !settings.features.noise;
  blur_known_ = !settings.features.blur;
  if (settings.blur_sigma_px >= 0) radiometry_.blur_sigma_px = settings.blur_sigma_px, blur_known_ = true;
  compositor_->set_object_shading(quality_.shading);
  compositor_->renderer().set_coverage_mesh_error(quality_.coverage_mesh_px);
  compositor_->renderer().set_video_radiometry(radiometry_);
  lighting_cells_ = settings.adapt_lighting_cells;
  set_adapt_lighting_every(settings.adapt_lighting_every);
}

// The first frame, and every kRetry-th until both are known (a camera may start on a
// blank wall): the sensor's noise from the frame's flat patches, the blur from its
// sharpest edges in the undistorted image the composite shows.
void Overlay::measure_camera(const cv::Mat& video) {
  constexpr std::int64_t kRetry = 30;
  if ((noise_known_ && blur_known_) || frames_seen_++ % kRetry != 0) return;
  std::string failed;
  if (!noise_known_) try {
      const calib::SensorNoise noise = calib::estimate_sensor_noise({video}, response_);
      for (int c = 0; c < 3; ++c) {
        radiometry_.noise_read_variance[std::size_t(c)] = float(noise.read_variance[std::size_t(c)]);
        radiometry_.noise_shot_gain[std::size_t(c)] = float(noise.shot_gain[std::size_t(c)]);
      }
      noise_known_ = true;
      spdlog::debug("camera noise: sigma {:.4f} (B) {:.4f} (G) {:.4f} (R) at linear 0.18, from {} flat patches",
                    noise.sigma(0, 0.18), noise.sigma(1, 0.18), noise.sigma(2, 0.18), noise.patches);
    } catch (const InputError& e) {
      failed += std::string(e.what()) + "; ";
    }
  if (!blur_known_) try {
      const calib::CameraBlur blur =
          calib::estimate_camera_blur(calib::undistort_in_linear_light(video, maps_, response_));
      // Antialiasing already averages each pixel's area, a box of variance 1/12 px², and
      // the renderer resamples what it rendered as the undistortion did the video, after
      // the clipping; the Gaussian is what is left, the blur before the clipping.
      const double box = compositor_->renderer().features().antialiasing ? 1.0 / 12.0 : 0.0;
      const double before_clipping = blur.sigma_px * blur.sigma_px - box - resampling_variance_;
      radiometry_.blur_sigma_px = std::min(4.0, std::sqrt(std::max(0.0, before_clipping)));
      blur_known_ = true;
      spdlog::debug("camera blur: sigma {:.2f} px from {} edge pixels", blur.sigma_px, blur.edges);
    } catch (const InputError& e) {
      failed += std::string(e.what()) + "; ";
    }
  if (!failed.empty() && !warned_) {
    spdlog::warn("overlay: the camera's noise or blur cannot be measured yet, trying again every {} frames: {}", kRetry,
                 failed.substr(0, failed.size() - 2));
    warned_ = true;
  }
  compositor_->renderer().set_video_radiometry(radiometry_);
}

void Overlay::set_adapt_lighting_every(int every_n_frames) {
  if (live_lighting_) live_lighting_->restore(*compositor_);
  live_lighting_.reset();
  lighting_every_ = every_n_frames;
  if (every_n_frames > 0)
    live_lighting_.emplace(
        camera_, maps_, response_, session_radiometry_,
        LiveLightingSettings{
            .every_n_frames = every_n_frames, .cell_cols = lighting_cells_, .background = live_ || window_});
}

void Overlay::set_scene(std::shared_ptr<const LoadedScene> scene) {
  context_->make_current();
  // The lighting measured so far was the old scene's map's: start again.
  live_lighting_.reset();
  const gl::CompositeFeatures features = compositor_->renderer().features();
  quality_.shading = compositor_->object_shading();
  quality_.shadows = compositor_->shadow_quality();
  quality_.coverage_mesh_px = compositor_->renderer().coverage_mesh_error();
  scene_ = scene;
  compositor_.reset();  // its GL objects go first
  compositor_ =
      std::make_unique<Compositor>(with_volume_knobs(std::move(scene), quality_), maps_.output, maps_.map_x,
                                   maps_.map_y, CompositorSettings{volume_cache_, features, quality_.shadows});
  compositor_->set_object_shading(quality_.shading);
  compositor_->renderer().set_coverage_mesh_error(quality_.coverage_mesh_px);
  compositor_->renderer().set_video_radiometry(radiometry_);
  set_adapt_lighting_every(lighting_every_);
  frames_since_clip_check_ = kClipCheckEvery, clip_warned_ = false;  // other objects may clip
}

void Overlay::set_quality(const OverlayQuality& quality) {
  check_quality(quality);
  if (quality.exact_lights != quality_.exact_lights || quality.shadow_map != quality_.shadow_map) {
    quality_.exact_lights = quality.exact_lights, quality_.shadow_map = quality.shadow_map;
    // The objects stay where they are; a new compositor would put them back at the manifest's poses.
    std::vector<glm::dmat4> poses;
    for (std::size_t i = 0; i < compositor_->scene().objects.size(); ++i) poses.push_back(compositor_->object_pose(i));
    set_scene(scene_);
    for (std::size_t i = 0; i < poses.size(); ++i) compositor_->set_object_pose(i, poses[i]);
  }
  quality_ = quality;
  compositor_->set_object_shading(quality.shading);
  compositor_->set_shadow_quality(quality.shadows);
  compositor_->renderer().set_coverage_mesh_error(quality.coverage_mesh_px);
}

OverlayQuality Overlay::quality() const {
  OverlayQuality q = quality_;
  q.shading = compositor_->object_shading();
  q.shadows = compositor_->shadow_quality();
  q.coverage_mesh_px = compositor_->renderer().coverage_mesh_error();
  return q;
}

void Overlay::play_paths(Nanos frame_time) { move_along_paths(frame_time, true); }

double Overlay::path_seconds(Nanos frame_time) const {
  return nanos_to_seconds(live_ ? frame_time - first_frame_time_.value_or(frame_time) : frame_time);
}

std::vector<Nanos> Overlay::shutter_times(Nanos frame_time) const {
  if (!(shutter_s_ > 0.0) || !compositor_->renderer().features().motion_blur) return {};
  // Each instant in the middle of its share of the shutter, as the synthetic camera's.
  std::vector<Nanos> out;
  for (int i = 0; i < shutter_instants_; ++i)
    out.push_back(frame_time + seconds_to_nanos(((i + 0.5) / shutter_instants_ - 0.5) * shutter_s_));
  return out;
}

std::vector<std::optional<Pose>> Overlay::shutter_cameras(
    Nanos frame_time, const std::optional<Pose>& pose,
    const std::function<std::optional<Pose>(Nanos)>& tracked_at) const {
  const std::vector<Nanos> times = shutter_times(frame_time);
  if (!pose || times.empty()) return {};
  const std::optional<Pose> tracked = tracked_at(frame_time);
  std::vector<std::optional<Pose>> out;
  for (const Nanos t : times) {
    if (t == frame_time) {  // the renderer draws that instant once
      out.push_back(pose);
      continue;
    }
    const std::optional<Pose> then = tracked_at(t);
    out.push_back(tracked && then ? std::optional<Pose>(*pose * tracked->inverse() * *then) : std::nullopt);
  }
  return out;
}

void Overlay::move_along_paths(Nanos frame_time, bool renderer_too) {
  if (!first_frame_time_) first_frame_time_ = frame_time;
  const double t_s = path_seconds(frame_time);
  const auto& objects = compositor_->scene().objects;
  for (std::size_t i = 0; i < objects.size(); ++i)
    if (!objects[i].path.empty()) {
      if (renderer_too)
        compositor_->set_object_pose(i, objects[i].pose_at(t_s));
      else
        compositor_->move_object(i, objects[i].pose_at(t_s));
    }
}

FrameLight Overlay::prepare(Nanos frame_time) {
  if (!can_prepare_ahead())
    throw RuntimeError("overlay: cannot prepare frames ahead while the lighting is adapted; use composite()");
  move_along_paths(frame_time, false);
  return compositor_->prepare();
}

OverlayFrame Overlay::render(const capture::Frame& frame, const std::optional<Pose>& T_world_camera,
                             const FrameLight& light, std::span<const std::optional<Pose>> shutter_cameras) {
  OverlayFrame out = begin(frame, T_world_camera);
  draw(out, frame, light, shutter_cameras);
  return out;
}

OverlayFrame Overlay::begin(const capture::Frame& frame, const std::optional<Pose>& T_world_camera) {
  OverlayFrame out;
  out.index = frame.index;
  out.time = frame.time;
  out.video = frame.image;
  out.T_world_camera = T_world_camera;
  if (!T_world_camera) ++frames_without_pose_;
  // A process may hold several overlays (the benchmark's with and without features),
  // each with its own context: draw in this one's.
  context_->make_current();
  // The codec's chroma sampling comes with the frames (a camera may switch formats).
  if (const auto block = frame.chroma;
      block.horizontal != radiometry_.chroma_horizontal || block.vertical != radiometry_.chroma_vertical) {
    // The renderer follows 1 or 2 each way; a coarser codec (4:1:1) is taken as the nearest it follows.
    radiometry_.chroma_horizontal = std::clamp(block.horizontal, 1, 2);
    radiometry_.chroma_vertical = std::clamp(block.vertical, 1, 2);
    compositor_->renderer().set_video_radiometry(radiometry_);
  }
  const auto measure_start = std::chrono::steady_clock::now();
  measure_camera(frame.image);
  times_.measure += ms_since(measure_start);
  return out;
}

Overlay::~Overlay() {
  compositor_.reset();  // GL objects go before their context
  context_.reset();
}

OverlayFrame Overlay::composite(const capture::Frame& frame, const std::optional<Pose>& T_world_camera,
                                std::span<const std::optional<Pose>> shutter_cameras) {
  OverlayFrame out = begin(frame, T_world_camera);
  play_paths(frame.time);
  if (live_lighting_ && T_world_camera) {
    const auto t0 = std::chrono::steady_clock::now();
    live_lighting_->update(*compositor_, frame.image, *T_world_camera, frame.time);
    out.lighting_scale = live_lighting_->scale();
    out.lighting_settled = !live_lighting_->transition();
    times_.lighting += ms_since(t0);
  }
  draw(out, frame, compositor_->prepare(), shutter_cameras);
  return out;
}

void Overlay::draw(OverlayFrame& out, const capture::Frame& frame, const FrameLight& light,
                   std::span<const std::optional<Pose>> shutter_cameras) {
  const std::optional<Pose>& T_world_camera = out.T_world_camera;
  // The shutter's instants: the camera as given, the animated objects where their paths
  // are then, the others where this frame has them.
  std::vector<gl::ShutterInstant> shutter;
  const std::vector<Nanos> times = shutter_times(frame.time);
  if (T_world_camera && !times.empty() && shutter_cameras.size() == times.size() &&
      std::all_of(shutter_cameras.begin(), shutter_cameras.end(), [](const auto& c) { return c.has_value(); })) {
    const auto& objects = compositor_->scene().objects;
    for (std::size_t k = 0; k < times.size(); ++k) {
      gl::ShutterInstant& instant = shutter.emplace_back();
      instant.T_world_camera = *shutter_cameras[k];
      for (std::size_t i = 0; i < objects.size(); ++i)
        instant.T_world_model.push_back(objects[i].path.empty() ? light.poses.at(i)
                                                                : objects[i].pose_at(path_seconds(times[k])));
    }
  }
  gl::OverlayTimings gt;
  out.composite = compositor_->render(light, frame.image, T_world_camera, exposure_ * exposure_scale_, &gt, shutter);
  times_.shadows += gt.shadows_ms;
  times_.vertex_light += gt.vertex_light_ms;
  times_.upload += gt.upload_ms;
  times_.background += gt.background_ms;
  times_.depth += gt.depth_ms;
  times_.objects += gt.objects_ms;
  times_.antialiasing += gt.antialiasing_ms;
  times_.motion_blur += gt.motion_blur_ms;
  times_.blur += gt.blur_ms;
  times_.readback += gt.readback_ms;
  if (T_world_camera && ++frames_since_clip_check_ >= kClipCheckEvery) measure_clipping(out.composite, *T_world_camera);
  ++times_.frames;
  if (!first_composite_) first_composite_ = std::chrono::steady_clock::now();
}

void Overlay::measure_clipping(const cv::Mat& composite, const Pose& T_world_camera) {
  frames_since_clip_check_ = 0;
  const cv::Mat mask = compositor_->renderer().render_object_mask(T_world_camera);
  const int covered = cv::countNonZero(mask);
  if (covered == 0 || mask.size() != composite.size()) return;
  // White in luma (JFIF's): the codec's chroma (4:2:0) gives a clipped pixel by the outline
  // some of its neighbours' colour, but keeps its luma.
  cv::Mat luma;
  cv::transform(composite, luma, cv::Matx13f(0.114f, 0.587f, 0.299f));  // B, G, R
  const cv::Mat white = luma >= 253.5f;
  objects_clipped_ = double(cv::countNonZero(white & mask)) / covered;
  if (*objects_clipped_ > kClipWarnShare && !clip_warned_) {
    clip_warned_ = true;
    spdlog::warn(
        "overlay: {:.0f} % of the objects' pixels clip to white: they are brighter than the camera records at this "
        "exposure (a truth frame, lumar synth --truth, shows whether a real object would clip too)",
        100.0 * *objects_clipped_);
  }
}

std::vector<std::pair<std::string, double>> StageTimes::stages() const {
  return {{"decode video", decode},
          {"tracker pose", pose},
          {"camera noise and blur", measure},
          {"lighting adaptation", lighting},
          {"shadows (moved objects)", shadows},
          {"object light per vertex", vertex_light},
          {"upload frame", upload},
          {"background (undistort)", background},
          {"proxy depth", depth},
          {"virtual objects", objects},
          {"antialiasing", antialiasing},
          {"motion blur", motion_blur},
          {"camera blur", blur},
          {"read back", readback},
          {"encode output", output}};
}

double StageTimes::total() const {
  double sum = 0;
  for (const auto& [name, ms] : stages()) sum += ms;
  return sum;
}

std::string format_stage_times(const StageTimes& t) {
  const int n = std::max(1, t.frames);
  const double total = t.total();
  std::string text = fmt::format("{:<24}{:>10}{:>8}\n", "stage", "ms/frame", "share");
  for (const auto& [name, ms] : t.stages())
    text += fmt::format("{:<24}{:>10.2f}{:>7.1f}%\n", name, ms / n, total > 0 ? 100.0 * ms / total : 0.0);
  text += fmt::format("{:<24}{:>10.2f}   ({:.1f} frames/s over {} frames)\n", "total", total / n,
                      total > 0 ? 1000.0 * n / total : 0.0, t.frames);
  return text;
}

std::string stage_times_json(const StageTimes& t, double wall_seconds, double startup_ms, const std::string& quality) {
  const int n = std::max(1, t.frames);
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, ms] : t.stages()) stages[name] = ms / n;
  const nlohmann::json out = {{"frames", t.frames},
                              {"fps", wall_seconds > 0 ? t.frames / wall_seconds : 0.0},
                              {"latency_ms_mean", t.latency / n},
                              {"startup_ms", startup_ms >= 0 ? nlohmann::json(startup_ms) : nlohmann::json()},
                              {"quality", quality.empty() ? nlohmann::json() : nlohmann::json(quality)},
                              {"stages", stages}};
  return out.dump(2) + "\n";
}

}  // namespace lumar::pipeline
