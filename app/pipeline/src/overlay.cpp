#include "lumar/pipeline/overlay.h"

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>

#include "lumar/base/error.h"

namespace lumar::pipeline {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

gl::VideoRadiometry video_radiometry(const capture::Radiometry& radiometry, const CameraIntrinsics& camera,
                                     const std::optional<calib::CameraResponse>& response) {
  gl::VideoRadiometry out;
  out.video_camera = camera;
  out.vignetting_a = radiometry.vignetting_a;
  out.vignetting_b = radiometry.vignetting_b;
  if (response) out.linear_of_code.assign(response->exposure.begin(), response->exposure.end());
  return out;
}

}  // namespace

Overlay::Overlay(std::shared_ptr<const LoadedScene> scene, const CameraIntrinsics& camera,
                 const capture::Radiometry& radiometry, const std::optional<calib::CameraResponse>& response,
                 const OverlaySettings& settings)
    : exposure_(radiometry.exposure) {
  if (settings.window) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display)
      throw RuntimeError(
          "overlay: no display to open a window on (DISPLAY is not set); to run headless, leave out --window and "
          "give --out or --frames-dir (the live path too), or run under xvfb-run");
    auto w = std::make_unique<gl::WindowContext>(camera.width, camera.height, settings.window_title);
    window_ = w.get();
    context_ = std::move(w);
  } else {
    context_ = gl::create_headless_context();
  }
  const calib::UndistortionMaps maps = calib::make_undistortion_maps(camera, settings.undistortion);
  compositor_ =
      std::make_unique<Compositor>(std::move(scene), maps.output, maps.map_x, maps.map_y, settings.volume_cache);
  compositor_->renderer().set_video_radiometry(video_radiometry(radiometry, camera, response));
  if (settings.adapt_lighting_every > 0)
    live_lighting_.emplace(camera, maps, response.value_or(calib::srgb_response(1.0)), radiometry,
                           settings.adapt_lighting_every);
}

Overlay::~Overlay() {
  compositor_.reset();  // GL objects go before their context
  context_.reset();
}

OverlayFrame Overlay::composite(const capture::Frame& frame, const std::optional<Pose>& T_world_camera) {
  OverlayFrame out;
  out.index = frame.index;
  out.time = frame.time;
  out.video = frame.image;
  out.T_world_camera = T_world_camera;
  if (!T_world_camera) ++frames_without_pose_;
  if (live_lighting_ && T_world_camera) {
    const auto t0 = std::chrono::steady_clock::now();
    out.lighting_scale = live_lighting_->update(compositor_->renderer(), frame.image, *T_world_camera, frame.time);
    times_.lighting += ms_since(t0);
  }
  // The map's light scaled as the room changed: the objects' radiance scales with it.
  gl::OverlayTimings gt;
  out.composite = compositor_->composite(frame.image, T_world_camera, exposure_ * out.lighting_scale, &gt);
  times_.upload += gt.upload_ms;
  times_.background += gt.background_ms;
  times_.depth += gt.depth_ms;
  times_.objects += gt.objects_ms;
  times_.readback += gt.readback_ms;
  ++times_.frames;
  return out;
}

std::string format_stage_times(const StageTimes& t) {
  const int n = std::max(1, t.frames);
  const std::pair<const char*, double> stages[] = {{"decode video", t.decode},
                                                   {"tracker pose", t.pose},
                                                   {"lighting adaptation", t.lighting},
                                                   {"upload frame", t.upload},
                                                   {"background (undistort)", t.background},
                                                   {"proxy depth", t.depth},
                                                   {"virtual objects", t.objects},
                                                   {"read back", t.readback},
                                                   {"encode output", t.output}};
  double total = 0;
  for (const auto& s : stages) total += s.second;
  std::string text = fmt::format("{:<24}{:>10}{:>8}\n", "stage", "ms/frame", "share");
  for (const auto& [name, ms] : stages)
    text += fmt::format("{:<24}{:>10.2f}{:>7.1f}%\n", name, ms / n, total > 0 ? 100.0 * ms / total : 0.0);
  text += fmt::format("{:<24}{:>10.2f}   ({:.1f} frames/s over {} frames)\n", "total", total / n,
                      total > 0 ? 1000.0 * n / total : 0.0, t.frames);
  return text;
}

}  // namespace lumar::pipeline
