#include "lumar/pipeline/live_lighting.h"

#include <opencv2/imgproc.hpp>

#include "lumar/calib/vignetting.h"

namespace lumar::pipeline {

namespace {
constexpr int kShrink = 4;

calib::LightingAdapterSettings adapter_settings(const calib::CameraResponse& response, double exposure) {
  calib::LightingAdapterSettings s;
  // Near-clipped video says nothing about how bright the room is.
  s.max_observed = response(1, 250) / exposure;
  s.min_pixels = 200;
  return s;
}
}  // namespace

LiveLighting::LiveLighting(const CameraIntrinsics& video_camera, const calib::UndistortionMaps& maps,
                           const calib::CameraResponse& response, const capture::Radiometry& radiometry,
                           int every_n_frames)
    : map_x_(maps.map_x),
      map_y_(maps.map_y),
      response_(response),
      exposure_(radiometry.exposure),
      every_(std::max(1, every_n_frames)),
      adapter_(adapter_settings(response, radiometry.exposure)) {
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

double LiveLighting::update(gl::Renderer& renderer, const cv::Mat& video_bgr8, const Pose& T_world_camera, Nanos time) {
  if (calls_++ % every_ != 0) return scale();
  // Observed radiance: linearise, undo vignetting and exposure, undistort, shrink.
  cv::Mat linear = calib::linearize(video_bgr8, response_);
  std::vector<cv::Mat> channels;
  cv::split(linear, channels);
  for (auto& c : channels) cv::multiply(c, inverse_gain_, c, 1.0 / exposure_);
  cv::merge(channels, linear);
  cv::Mat undistorted, observed;
  cv::remap(linear, undistorted, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::resize(undistorted, observed, cv::Size(small_camera_.width, small_camera_.height), 0, 0, cv::INTER_AREA);

  const cv::Mat predicted = renderer.render_room_radiance(small_camera_, T_world_camera);
  // Virtual objects are not the room: leave out their pixels (and a margin around them).
  cv::Mat objects = renderer.render_object_mask(T_world_camera), small_objects, valid;
  cv::resize(objects, small_objects, observed.size(), 0, 0, cv::INTER_AREA);
  cv::dilate(small_objects, small_objects, cv::Mat());
  cv::compare(small_objects, 0, valid, cv::CMP_EQ);
  adapter_.update(observed, predicted, time, valid);
  ++measurements_;
  return scale();
}

}  // namespace lumar::pipeline
