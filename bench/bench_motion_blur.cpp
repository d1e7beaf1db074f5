// The objects' motion blur against the truth of a camera whose shutter stays open (synth
// --motion-blur; docs/ground_truth.md, "Motion blur"), for its one knob, the instants of
// the shutter the objects are drawn at: each region's error against milliseconds per
// frame, through the pipeline library `lumar regress` runs. Baseline, in the same run: the
// composite without motion blur. Two recordings: the walk's figurine passing a still camera
// (12 frames/s, 80 ms shutter) and a fast orbit (8 frames/s, 100 ms shutter, the camera
// turning 7 degrees while it is open). Writes docs/motion_blur_error_vs_cost.png and
// docs/motion_blur_before_after_truth.png (the walking figurine: without, with, the truth).
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <opencv2/imgproc.hpp>

#include "bench_report.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/image_file.h"
#include "lumar/pipeline/truth_comparison.h"
#include "lumar/sim/synthetic_recording.h"

using namespace lumar;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = LUMAR_SOURCE_DIR;
const std::string kOff = "no motion blur";

struct Case {
  std::string name, scene, path;
  int frames = 0;
  double fps = 0, shutter_s = 0;
  std::vector<int> truth_frames;
};

}  // namespace

int main() {
  const fs::path out = fs::temp_directory_path() / fmt::format("lumar-bench-motion-blur-{}", ::getpid());
  fs::remove_all(out);
  const std::vector<Case> cases{{"walk", "walk.json", "still", 12, 12.0, 0.08, {3, 5, 7}},
                                {"orbit", "scene.json", "orbit", 8, 8.0, 0.1, {2, 3, 4}}};
  std::vector<bench::BenchReport> reports;
  cv::Mat before, after, truth, mask;
  for (const Case& c : cases) {
    sim::SynthSettings synth;
    synth.scene = kSource / "data/scenes/room" / c.scene;
    synth.camera = calib::load_camera_file(kSource / "data/camera/webcam-640x480.yml").intrinsics;
    synth.out = out / c.name;
    synth.path = c.path;
    synth.frames = c.frames;
    synth.fps = c.fps;
    synth.faults.motion_blur_s = c.shutter_s;
    synth.truth = true;
    synth.truth_frames = c.truth_frames;
    spdlog::info("motion blur bench: rendering the {} ({} frames, truth on {}) into {}", c.name, c.frames,
                 c.truth_frames.size(), synth.out.string());
    sim::synthesize_recording(synth);

    const std::size_t first = reports.size();
    for (const char* region : {"object", "edge"}) {
      bench::BenchReport& r = reports.emplace_back();
      r.name = fmt::format("motion_blur_{}_{}", c.name, region);
      r.title = fmt::format("Motion blur, {}: {} region", c.name, region);
      r.baseline = kOff;
      r.error_label = std::string(region) + " error (% of the truth)";
      r.highlight = "3 instants";
      r.note = fmt::format("{} frames/s, {:.0f} ms shutter, truth on {} frames; ms per frame on llvmpipe", c.fps,
                           1e3 * c.shutter_s, c.truth_frames.size());
    }
    for (const int instants : {0, 2, 3, 5, 8}) {
      pipeline::ReplayOverlaySettings settings;
      settings.overlay.features.motion_blur = instants > 0;
      settings.overlay.shutter_instants = std::max(instants, 2);
      const std::string name = instants > 0 ? fmt::format("{} instants", instants) : kOff;
      const auto compared = pipeline::compare_with_truth(
          synth.out, settings, [&](const pipeline::OverlayFrame& f, const cv::Mat& truth_frame, const cv::Mat& m) {
            if (c.name != "walk" || f.index != 5 || (instants != 0 && instants != 3)) return;
            (instants == 0 ? before : after) = f.composite.clone();
            truth = truth_frame;
            mask = m;
          });
      const pipeline::CompositeError& e = compared->error;
      reports[first].entries.push_back({name, compared->ms_per_frame, e.object_err});
      reports[first + 1].entries.push_back({name, compared->ms_per_frame, e.edge_err});
      spdlog::info("{:<6} {:<15} {:6.1f} ms/frame  object {:.2f} %  edge {:.2f} %  shadow {:.2f} %  (floors {:.2f} / "
                   "{:.2f} / {:.2f} %)",
                   c.name, name, compared->ms_per_frame, e.object_err, e.edge_err, e.shadow_err,
                   e.noise_floor_object_err, e.noise_floor_edge_err, e.noise_floor_shadow_err);
    }
  }
  for (auto& r : reports) r.compute_ratios();
  bench::publish_stacked(reports, "motion_blur_error_vs_cost.png");

  // The walking figurine (the mask's largest part), 3 times enlarged: without motion
  // blur, with it, the truth.
  std::vector<std::vector<cv::Point>> parts_of_mask;
  cv::findContours(mask.clone(), parts_of_mask, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::Rect box;
  for (const auto& part : parts_of_mask)
    if (cv::boundingRect(part).area() > box.area()) box = cv::boundingRect(part);
  const cv::Rect crop = cv::Rect(box.x - 16, box.y - 10, box.width + 32, box.height + 20) &
                        cv::Rect(0, 0, mask.cols, mask.rows);
  calib::write_image_atomically(kSource / "docs/motion_blur_before_after_truth.png",
                                bench::crops_side_by_side({before, after, truth}, crop, 3));
  fs::remove_all(out);
  std::printf("wrote docs/motion_blur_error_vs_cost.png and docs/motion_blur_before_after_truth.png\n");
  return 0;
}
