// The quality knobs of the overlay against its composite error and time per frame
// (issue 19): where the objects are lit (per pixel or per vertex, ObjectShading), the
// shadow lines per receiver and emitter patch (ShadowQuality), and the number of exact
// lights the volume evaluates with shadow maps (OverlaySettings::exact_lights). On a
// synthetic recording of the walk scene with its truth (the figurine moves, so its shadow
// and its light are traced again every frame), through the pipeline library `lumar
// regress` runs. Baseline: full quality (per pixel, 8 lines, 16 lights) in the same run.
// "auto" marks the cheapest setting whose object, edge and shadow errors each stay within
// 1.2 x full quality's. Writes docs/composite_error_vs_frame_time.png.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include "bench_report.h"
#include "lumar/calib/camera_file.h"
#include "lumar/pipeline/truth_comparison.h"
#include "lumar/sim/synthetic_recording.h"

using namespace lumar;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = LUMAR_SOURCE_DIR;
const fs::path kScene = kSource / "data/scenes/room/walk.json";

struct Knobs {
  bool vertex = false;
  int lines = 8, lights = 16;
  std::string name() const {
    return fmt::format("{}, {} lines, {} lights", vertex ? "vertex" : "pixel", lines, lights);
  }
};

}  // namespace

int main() {
  const fs::path out = fs::temp_directory_path() / fmt::format("lumar-bench-frame-budget-{}", ::getpid());
  fs::remove_all(out);
  sim::SynthSettings synth;
  synth.scene = kScene;
  synth.camera = calib::load_camera_file(kSource / "data/camera/webcam-640x480.yml").intrinsics;
  synth.out = out / "recording";
  synth.frames = 8;
  synth.truth = true;
  spdlog::info("frame budget bench: rendering {} frames of the walk and their truth into {}", synth.frames,
               out.string());
  sim::synthesize_recording(synth);

  std::vector<Knobs> settings;
  for (int lights : {16, 6, 2})
    for (bool vertex : {false, true})
      for (int lines : {8, 4, 2}) settings.push_back({vertex, lines, lights});
  std::vector<std::array<double, 3>> errors;
  std::vector<double> ms;
  for (const Knobs& knobs : settings) {
    pipeline::ReplayOverlaySettings s;
    s.overlay.exact_lights = knobs.lights;
    s.overlay.shading = knobs.vertex ? ObjectShading::PerVertex : ObjectShading::PerPixel;
    s.overlay.shadow_quality.lines_per_patch = knobs.lines;
    const auto compared = pipeline::compare_with_truth(synth.out, s);
    const pipeline::CompositeError& e = compared->error;
    errors.push_back({e.object_err, e.edge_err, e.shadow_err});
    ms.push_back(compared->ms_per_frame);
    spdlog::info("{:<28} {:6.1f} ms/frame  object {:.2f} %  edge {:.2f} %  shadow {:.2f} %", knobs.name(),
                 compared->ms_per_frame, e.object_err, e.edge_err, e.shadow_err);
  }
  // auto: the cheapest setting within the budget on every region.
  constexpr double kBudget = 1.2;
  std::size_t chosen = 0;
  for (std::size_t i = 0; i < settings.size(); ++i) {
    bool within = true;
    for (int k = 0; k < 3; ++k) within &= errors[i][std::size_t(k)] <= kBudget * errors[0][std::size_t(k)];
    if (within && ms[i] < ms[chosen]) chosen = i;
  }

  // One bar per setting, its time; its errors in its name. The regions' numbers as JSON.
  bench::BenchReport chart;
  chart.name = "frame_budget";
  chart.title = "Quality knobs: ms per frame (walk, 640x480, llvmpipe); errors object / edge / shadow vs truth";
  for (std::size_t i = 0; i < settings.size(); ++i)
    chart.entries.push_back({fmt::format("{}{}: {:.2f} / {:.2f} / {:.2f} %", i == chosen ? "auto = " : "",
                                         settings[i].name(), errors[i][0], errors[i][1], errors[i][2]),
                             ms[i]});
  chart.baseline = chart.entries.front().name;
  chart.compute_ratios();
  chart.save(bench::results_dir());
  const char* regions[3] = {"object", "edge", "shadow"};
  for (int k = 0; k < 3; ++k) {
    bench::BenchReport r;
    r.name = std::string("frame_budget_") + regions[k];
    r.title = std::string("Quality knobs vs truth: ") + regions[k] + " region";
    r.baseline = settings.front().name();
    r.error_label = std::string(regions[k]) + " error (% of the truth)";
    r.highlight = settings[chosen].name();
    for (std::size_t i = 0; i < settings.size(); ++i)
      r.entries.push_back({settings[i].name(), ms[i], errors[i][std::size_t(k)]});
    r.compute_ratios();
    r.write_json(bench::results_dir() / (r.name + ".json"));
  }
  fs::copy_file(bench::results_dir() / "frame_budget.png", kSource / "docs/composite_error_vs_frame_time.png",
                fs::copy_options::overwrite_existing);
  fs::remove_all(out);
  std::printf(
      "auto: %s, %.1f ms per frame (full quality %.1f ms, %.2fx); errors object %.2f %%, edge %.2f %%, shadow %.2f %% "
      "(full quality %.2f / %.2f / %.2f %%)\nwrote docs/composite_error_vs_frame_time.png\n",
      settings[chosen].name().c_str(), ms[chosen], ms[0], ms[chosen] / ms[0], errors[chosen][0], errors[chosen][1],
      errors[chosen][2], errors[0][0], errors[0][1], errors[0][2]);
  return 0;
}
