#include "lumar/pipeline/live_lighting.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <opencv2/imgproc.hpp>

#include "lumar/calib/vignetting.h"
#include "lumar/lighting/irradiance_volume.h"

namespace lumar::pipeline {

namespace {
constexpr int kShrink = 4;
constexpr int kClipCode = 250;  // video codes at or above are taken as clipped

calib::LightingAdapterSettings adapter_settings(const calib::CameraResponse& response, double exposure, int cols) {
  calib::LightingAdapterSettings s;
  s.cell_cols = std::max(1, cols);
  s.cell_rows = std::max(1, cols / 2);
  // Near-clipped video says only "at least this bright".
  s.max_observed = response(1, kClipCode) / exposure;
  return s;
}
}  // namespace

LiveLighting::LiveLighting(const CameraIntrinsics& video_camera, const calib::UndistortionMaps& maps,
                           const calib::CameraResponse& response, const capture::Radiometry& radiometry,
                           const LiveLightingSettings& settings)
    : settings_(settings),
      map_x_(maps.map_x),
      map_y_(maps.map_y),
      response_(response),
      exposure_(radiometry.exposure),
      adapter_(adapter_settings(response, radiometry.exposure, settings.cell_cols)) {
  settings_.every_n_frames = std::max(1, settings.every_n_frames);
  baked_version_ = adapter_.version();
  small_camera_ = maps.output.without_distortion();
  small_camera_.width = maps.output.width / kShrink;
  small_camera_.height = maps.output.height / kShrink;
  // Pixel centres at integers (OpenCV): x_small + 0.5 = (x + 0.5) / kShrink.
  small_camera_.fx /= kShrink;
  small_camera_.fy /= kShrink;
  small_camera_.cx = (maps.output.cx + 0.5) / kShrink - 0.5;
  small_camera_.cy = (maps.output.cy + 0.5) / kShrink - 0.5;
  const cv::Size video_size(video_camera.width, video_camera.height);
  cv::Mat gain = calib::vignetting_gain(video_size, radiometry.vignetting_a, radiometry.vignetting_b, video_camera.cx,
                                        video_camera.cy);
  cv::divide(1.0, gain, inverse_gain_);
}

LiveLighting::~LiveLighting() {
  if (pending_.valid()) pending_.wait();  // the bake reads the scene and the base radiance
}

// The captured map times the cells' ratios, and the lighting baked from it. Runs on the
// bake thread when live: it reads only the scene, the ratios and base_, which it makes
// the first time (no other thread touches base_ while a bake is pending).
LiveLighting::Baked LiveLighting::bake(const std::shared_ptr<const LoadedScene>& scene, const cv::Mat& ratios_bgr) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!base_) base_ = scene_base_radiance(*scene);
  MapCellScale scale{ratios_bgr.cols, ratios_bgr.rows, std::vector<glm::vec3>(ratios_bgr.total())};
  for (std::size_t k = 0; k < scale.rgb.size(); ++k) {
    const cv::Vec3d v = ratios_bgr.at<cv::Vec3d>(int(k));
    scale.rgb[k] = glm::vec3(float(v[2]), float(v[1]), float(v[0]));
  }
  Baked out;
  out.lighting = relit_scene_lighting(*scene, *base_, scale);
  out.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

void LiveLighting::start_fade(Baked baked, Nanos time) {
  ++bakes_;
  bake_ms_ = baked.ms;
  spdlog::debug("lighting: re-baked in {:.0f} ms; fading in over {:.2f} s", baked.ms, settings_.fade_s);
  to_ = std::move(baked.lighting);
  fading_ = true;
  fade_start_ = time;
}

void LiveLighting::restore(Compositor& compositor) const {
  if (bakes_ > 0) compositor.set_lighting(original_);
}

void LiveLighting::update(Compositor& compositor, const cv::Mat& video_bgr8, const Pose& T_world_camera, Nanos time) {
  if (!scene_) {
    // The compositor's own lighting is where every fade starts from, and what restore() returns to.
    scene_ = compositor.shared_scene();
    original_.volume = compositor.irradiance_volume();
    original_.sh = compositor.lighting_sh();
    const auto& s = adapter_.settings();
    original_.scale = MapCellScale{s.cell_cols, s.cell_rows,
                                   std::vector<glm::vec3>(std::size_t(s.cell_cols) * s.cell_rows, glm::vec3(1.0f))};
    from_ = original_;
  }
  if (calls_++ % settings_.every_n_frames == 0) {
    // Observed radiance: linearise, undo vignetting and exposure, undistort, shrink.
    cv::Mat linear = calib::linearize(video_bgr8, response_);
    std::vector<cv::Mat> channels;
    cv::split(linear, channels);
    for (auto& c : channels) cv::multiply(c, inverse_gain_, c, 1.0 / exposure_);
    cv::merge(channels, linear);
    cv::Mat undistorted, observed;
    cv::remap(linear, undistorted, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    cv::resize(undistorted, observed, cv::Size(small_camera_.width, small_camera_.height), 0, 0, cv::INTER_AREA);

    cv::Mat map_uv;
    const cv::Mat predicted = compositor.renderer().render_room_radiance(small_camera_, T_world_camera, &map_uv);
    // Virtual objects are not the room: leave out their pixels (and a margin around them).
    // Nor is clipped video, before it is averaged down with its neighbours: a lit lamp
    // clips, and its average would read as a lamp gone dim.
    cv::Mat objects = compositor.renderer().render_object_mask(T_world_camera), clipped, excluded, valid;
    std::vector<cv::Mat> bgr;
    cv::split(video_bgr8, bgr);
    cv::compare(cv::max(cv::max(bgr[0], bgr[1]), bgr[2]), kClipCode, clipped, cv::CMP_GE);
    cv::remap(clipped, clipped, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
    cv::max(objects, clipped, objects);
    cv::resize(objects, excluded, observed.size(), 0, 0, cv::INTER_AREA);
    cv::dilate(excluded, excluded, cv::Mat());
    cv::compare(excluded, 0, valid, cv::CMP_EQ);
    adapter_.update(observed, predicted, map_uv, time, valid);
    ++measurements_;
  }

  // A finished bake starts its fade; a moved measurement starts a bake once the last
  // change has faded in.
  if (pending_.valid() &&
      (!settings_.background || pending_.wait_for(std::chrono::seconds(0)) == std::future_status::ready))
    start_fade(pending_.get(), time);
  if (!fading_ && !pending_.valid() && adapter_.version() != baked_version_) {
    baked_version_ = adapter_.version();
    pending_ = std::async(settings_.background ? std::launch::async : std::launch::deferred, &LiveLighting::bake, this,
                          scene_, adapter_.cell_ratios());
    if (!settings_.background) start_fade(pending_.get(), time);
  }
  if (fading_) {
    const auto t0 = std::chrono::steady_clock::now();
    const double t = settings_.fade_s > 0 ? nanos_to_seconds(time - fade_start_) / settings_.fade_s : 1.0;
    if (t >= 1.0) {
      compositor.set_lighting(to_);
      from_ = to_;
      fading_ = false;
    } else {
      compositor.set_lighting(SceneLighting::blend(from_, to_, std::max(0.0, t)));
    }
    worst_fade_step_ms_ = std::max(
        worst_fade_step_ms_, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
}

}  // namespace lumar::pipeline
