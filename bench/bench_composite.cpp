// The composite against its ground truth for every combination of the features that make
// rendered pixels look like the camera's (antialiasing, self-occlusion, noise, blur:
// docs/ground_truth.md): each region's error against milliseconds per frame, through the
// pipeline library `lumar regress` runs, the bounce, the shadow lines and the codec's
// chroma on. Baseline, in the same run: the 2004 system's look (no antialiasing, no self-occlusion, no noise or
// blur, no bounce, bounding-sphere shadows: `--without all`). Writes
// docs/composite_error_vs_cost.png (object, edge and shadow, one above the other) and
// docs/composite_before_after_truth.png (crops at the figurine's feet: the 2004 look,
// every feature on, the truth) and docs/solid_scan_vs_closed.png (crops of the upper body:
// the composite with the figurine's open scan, with its closed solid, the truth;
// docs/solid.md).
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <nlohmann/json.hpp>

#include "bench_report.h"
#include "lumar/base/json_file.h"
#include "lumar/base/output_file.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/image_file.h"
#include "lumar/pipeline/truth_comparison.h"
#include "lumar/sim/synthetic_recording.h"

using namespace lumar;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = LUMAR_SOURCE_DIR;
const std::string k2004 = "2004: all off, no bounce, sphere shadows";

std::string name_of(const gl::CompositeFeatures& f) {
  std::string name;
  const auto add = [&](bool on, const char* what) {
    if (on) name += (name.empty() ? "" : "+") + std::string(what);
  };
  add(f.antialiasing, "aa");
  add(f.self_occlusion, "occlusion");
  add(f.noise, "noise");
  add(f.blur, "blur");
  return name.empty() ? "none of the four" : name;
}

// The figurine's feet and the floor around them: the bottom 40 % of the mask's box, widened.
cv::Rect feet(const cv::Mat& truth_mask) {
  const cv::Rect box = cv::boundingRect(truth_mask);
  const int h = std::max(40, box.height * 2 / 5);
  return cv::Rect(box.x - 12, box.y + box.height - h, box.width + 24, h + 12) &
         cv::Rect(0, 0, truth_mask.cols, truth_mask.rows);
}

// The sample room's scene with its figurine's open scan instead of the closed solid,
// written beside the recording (its paths made absolute).
fs::path scene_with_the_scan(const fs::path& dir) {
  const fs::path room = kSource / "data/scenes/room";
  nlohmann::json j = read_json_file(room / "scene.json", "scene manifest");
  j["room"]["mesh"] = (room / j["room"]["mesh"].get<std::string>()).lexically_normal().string();
  j["environment_map"]["path"] = (room / j["environment_map"]["path"].get<std::string>()).lexically_normal().string();
  for (auto& o : j["objects"]) o["mesh"] = (kSource / "data/models/parasaurolophus_6700.ply").string();
  const fs::path path = dir / "scene_with_the_scan.json";
  write_file_atomically(path, j.dump(2));
  return path;
}

}  // namespace

int main() {
  // The recording and its truth (about 20 MB) in a temporary folder, not among the results.
  const fs::path out = fs::temp_directory_path() / fmt::format("lumar-bench-composite-{}", ::getpid());
  fs::remove_all(out);
  sim::SynthSettings synth;
  synth.scene = kSource / "data/scenes/room/scene.json";
  synth.camera = calib::load_camera_file(kSource / "data/camera/webcam-640x480.yml").intrinsics;
  synth.out = out;
  synth.frames = 8;
  synth.truth = true;
  spdlog::info("composite bench: rendering {} frames and their truth into {}", synth.frames, out.string());
  sim::synthesize_recording(synth);

  std::vector<bench::BenchReport> reports(3);
  const char* regions[3] = {"object", "edge", "shadow"};
  for (int k = 0; k < 3; ++k) {
    reports[std::size_t(k)].name = std::string("composite_error_") + regions[k];
    reports[std::size_t(k)].title = std::string("Composite vs truth: ") + regions[k] + " region";
    reports[std::size_t(k)].baseline = k2004;
    reports[std::size_t(k)].error_label = std::string(regions[k]) + " error (% of the truth)";
    reports[std::size_t(k)].highlight = "aa+occlusion+noise+blur";
  }
  cv::Mat before, after, truth, mask;
  // bits 0-15: the four features' combinations (bounce, the shadow lines and the chroma
  // on); -1: the 2004 system (every feature off, bounce off, the bounding-sphere shadows).
  for (int bits = -1; bits < 16; ++bits) {
    pipeline::ReplayOverlaySettings settings;
    if (bits < 0)
      settings.overlay.features = gl::CompositeFeatures::none();
    else
      settings.overlay.features = {bool(bits & 1), bool(bits & 2), bool(bits & 4), bool(bits & 8)};
    const std::string name = bits < 0 ? k2004 : name_of(settings.overlay.features);
    const auto compared = pipeline::compare_with_truth(
        out, settings, [&](const pipeline::OverlayFrame& f, const cv::Mat& truth_frame, const cv::Mat& truth_mask) {
          if (f.index != synth.frames - 1 || (bits != -1 && bits != 15)) return;
          (bits < 0 ? before : after) = f.composite.clone();
          truth = truth_frame;
          mask = truth_mask;
        });
    const pipeline::CompositeError& e = compared->error;
    const double errors[3] = {e.object_err, e.edge_err, e.shadow_err};
    for (int k = 0; k < 3; ++k) reports[std::size_t(k)].entries.push_back({name, compared->ms_per_frame, errors[k]});
    spdlog::info("{:<26} {:6.1f} ms/frame  object {:.2f} %  edge {:.2f} %  shadow {:.2f} %  noise ratio {:.2f}", name,
                 compared->ms_per_frame, e.object_err, e.edge_err, e.shadow_err, e.noise_ratio);
  }
  for (auto& r : reports) {
    r.note = "8 frames of the sample room's orbit with their truth; ms per frame (decode to read-back) on llvmpipe";
    r.compute_ratios();
  }
  bench::publish_stacked(reports, "composite_error_vs_cost.png");

  // The last frame's feet, 4 times enlarged: before, after, truth.
  calib::write_image_atomically(kSource / "docs/composite_before_after_truth.png",
                                bench::crops_side_by_side({before, after, truth}, feet(mask), 4));
  // The same frame with the open scan the solid was made from: its cracks show back faces
  // and, in its truth, a hollow inside (docs/solid.md). Against the solid's truth, so the
  // errors say how far the scan's composite is from the closed figurine's look.
  cv::Mat scan;
  pipeline::ReplayOverlaySettings with_scan;
  with_scan.scene = scene_with_the_scan(out);
  const auto scan_compared = pipeline::compare_with_truth(
      out, with_scan, [&](const pipeline::OverlayFrame& f, const cv::Mat&, const cv::Mat&) {
        if (f.index == synth.frames - 1) scan = f.composite.clone();
      });
  spdlog::info("the open scan, every feature on: object {:.2f} %  edge {:.2f} %  specks {}",
               scan_compared->error.object_err, scan_compared->error.edge_err, scan_compared->error.specks);
  const cv::Rect box = cv::boundingRect(mask);
  const cv::Rect upper =
      cv::Rect(box.x - 6, box.y - 6, box.width + 12, box.height * 3 / 5) & cv::Rect(0, 0, mask.cols, mask.rows);
  calib::write_image_atomically(kSource / "docs/solid_scan_vs_closed.png",
                                bench::crops_side_by_side({scan, after, truth}, upper, 3));
  fs::remove_all(out);
  std::printf(
      "wrote docs/composite_error_vs_cost.png, docs/composite_before_after_truth.png and "
      "docs/solid_scan_vs_closed.png\n");
  return 0;
}
