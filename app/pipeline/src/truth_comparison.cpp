#include "lumar/pipeline/truth_comparison.h"

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>

#include "lumar/base/error.h"
#include "lumar/calib/undistortion.h"

namespace lumar::pipeline {

std::optional<TruthComparison> compare_with_truth(const std::filesystem::path& dir, ReplayOverlaySettings settings,
                                                  const TruthFrameVisitor& visit) {
  const std::filesystem::path truth = dir / "truth";
  if (!std::filesystem::is_directory(truth)) return std::nullopt;
  settings.poses = PoseSource::Truth;
  ReplayOverlay overlay(dir, settings);
  // The overlay's own maps and response: the truth is undistorted as its video is.
  const calib::UndistortionMaps& maps = overlay.overlay().undistortion();
  const calib::CameraResponse& response = overlay.overlay().response();
  CompositeErrorMeter meter(response);
  const auto file = [&](const char* kind, std::int64_t index) {
    return truth / fmt::format("{}-{:05d}.png", kind, index);
  };
  const auto read = [&](const char* kind, std::int64_t index, int flags) {
    const std::filesystem::path path = file(kind, index);
    // Checked first: OpenCV would warn on its own line about a missing file.
    const cv::Mat image = std::filesystem::exists(path) ? cv::imread(path.string(), flags) : cv::Mat();
    if (image.empty()) throw InputError(path.string() + ": missing or unreadable truth frame");
    if (image.size() != maps.map_x.size())
      throw InputError(path.string() + ": truth frame is " + std::to_string(image.cols) + "x" +
                       std::to_string(image.rows) + ", not the video's size");
    // Resampled in linear light, as the composite's background is (the mask by value).
    return image.channels() == 3 ? calib::undistort_in_linear_light(image, maps, response)
                                 : calib::undistort_image(image, maps);
  };
  const auto total_ms = [&] { return overlay.overlay().times().total(); };
  // The first frame pays for the shaders' compilation: timed from the second on.
  double after_first = 0;
  int frames = 0, measured = 0;
  overlay.run(0, [&](const OverlayFrame& f) {
    if (frames++ == 0) after_first = total_ms();
    // A frame has truth where its truth/frame-*.png is (synth --truth-frames).
    if (!f.T_world_camera || !std::filesystem::exists(file("frame", f.index))) return true;
    ++measured;
    const cv::Mat mask = read("mask", f.index, cv::IMREAD_GRAYSCALE) > 127;
    const cv::Mat frame = read("frame", f.index, cv::IMREAD_COLOR);
    meter.add(f.composite, frame, read("other-seed", f.index, cv::IMREAD_COLOR),
              read("empty", f.index, cv::IMREAD_COLOR), mask);
    if (visit) visit(f, frame, mask);
    return true;
  });
  if (measured == 0) throw InputError(truth.string() + ": no truth frame for any frame of the video");
  const double ms = frames > 1 ? (total_ms() - after_first) / (frames - 1) : total_ms();
  return TruthComparison{meter.result(), ms, overlay.quality_choice()};
}

}  // namespace lumar::pipeline
