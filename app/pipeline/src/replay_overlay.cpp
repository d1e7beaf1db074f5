#include "lumar/pipeline/replay_overlay.h"

#include <fmt/format.h>
#include <chrono>

#include "lumar/base/error.h"
#include "lumar/calib/camera_response.h"
#include "lumar/calib/undistortion.h"

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

ReplayOverlay::ReplayOverlay(const std::filesystem::path& recording, const std::filesystem::path& scene_override,
                             PoseSource poses, bool window, calib::UndistortedCamera undistortion,
                             int adapt_lighting_every)
    : replay_(recording), pose_source_(poses) {
  const std::filesystem::path scene_path = scene_override.empty() ? replay_.scene_path() : scene_override;
  if (scene_path.empty()) throw InputError((recording / "session.json").string() + ": names no scene; pass --scene");
  scene_ = std::make_shared<const LoadedScene>(load_scene_files(scene_path));
  if (poses == PoseSource::Truth && replay_.reader().truth().empty())
    throw InputError(recording.string() + ": has no ground truth (truth.csv); use the tracker's poses");

  const CameraIntrinsics& camera = replay_.session().camera;
  if (window) {
    auto w = std::make_unique<gl::WindowContext>(camera.width, camera.height, "lumar overlay");
    window_ = w.get();
    context_ = std::move(w);
  } else {
    context_ = gl::create_headless_context();
  }
  const calib::UndistortionMaps maps = calib::make_undistortion_maps(camera, undistortion);
  compositor_ = std::make_unique<Compositor>(scene_, maps.output, maps.map_x, maps.map_y);
  const auto& radiometry = replay_.session().radiometry;
  const auto response = calib::calibrated_response(radiometry, recording);
  compositor_->renderer().set_video_radiometry(video_radiometry(radiometry, camera, response));
  if (adapt_lighting_every > 0)
    live_lighting_.emplace(camera, maps, response.value_or(calib::srgb_response(1.0)), radiometry,
                           adapt_lighting_every);
}

ReplayOverlay::~ReplayOverlay() {
  compositor_.reset();  // GL objects go before their context
  context_.reset();
}

void ReplayOverlay::run(int max_frames, const std::function<bool(const OverlayFrame&)>& sink) {
  auto frames = replay_.open_frames();
  const double exposure = replay_.session().radiometry.exposure;
  capture::Frame frame;
  for (int n = 0; max_frames <= 0 || n < max_frames; ++n) {
    auto t0 = std::chrono::steady_clock::now();
    if (!frames->read(frame)) break;
    times_.decode += ms_since(t0);

    t0 = std::chrono::steady_clock::now();
    OverlayFrame out;
    out.index = frame.index;
    out.time = frame.time;
    out.video = frame.image;
    out.T_world_camera = pose_source_ == PoseSource::Truth ? replay_.true_camera_pose(frame.index)
                                                           : replay_.tracked_camera_pose(frame.time);
    times_.pose += ms_since(t0);

    gl::OverlayTimings gt;
    if (!out.T_world_camera) ++frames_without_pose_;
    double lighting_scale = 1.0;
    if (live_lighting_ && out.T_world_camera) {
      t0 = std::chrono::steady_clock::now();
      lighting_scale = live_lighting_->update(compositor_->renderer(), frame.image, *out.T_world_camera, frame.time);
      times_.lighting += ms_since(t0);
    }
    // The map's light scaled as the room changed: the objects' radiance scales with it.
    out.composite = compositor_->composite(frame.image, out.T_world_camera, exposure * lighting_scale, &gt);
    out.lighting_scale = lighting_scale;
    times_.upload += gt.upload_ms;
    times_.background += gt.background_ms;
    times_.depth += gt.depth_ms;
    times_.objects += gt.objects_ms;
    times_.readback += gt.readback_ms;

    t0 = std::chrono::steady_clock::now();
    const bool go_on = sink(out);
    times_.output += ms_since(t0);
    ++times_.frames;
    if (!go_on) break;
  }
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
