// Lighting that follows the room (issue 18): how finely the map's directions are cut into
// cells (the knob, LiveLightingSettings::cell_cols; half as many rows) against how close
// the figurine's irradiance ends to the volume built from the changed map, and what the
// adaptation costs per frame (the overlay's "lighting adaptation" stage: the comparison
// every 2nd frame, the re-bakes, which a replay runs at once, and the fades). Recordings:
// the sample room's lamp going out and window turning warmer
// (sim::sample_room_light_changes), replayed with true poses; the error is the mean of the
// two at their last frame. The baseline is the default, 32 columns.
// Writes bench/results/lighting_change_error_vs_time.{json,png} and
// docs/lighting_change_error_vs_time.png.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <map>

#include "bench_report.h"
#include "lumar/calib/camera_file.h"
#include "lumar/pipeline/lighting_followed.h"
#include "lumar/sim/light_change.h"
#include "lumar/sim/synthetic_recording.h"

using namespace lumar;

namespace {

const std::filesystem::path kSource = LUMAR_SOURCE_DIR;
const std::vector<int> kColumns = {4, 8, 16, 32, 64};

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path scene = kSource / "data/scenes/room/scene.json";
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("lumar-bench-lighting-{}", ::getpid());
  std::filesystem::remove_all(dir);
  const auto recordings = sim::sample_room_light_changes(
      scene, calib::load_camera_file(kSource / "data/camera/webcam-640x480.yml").intrinsics, dir);
  const LoadedScene loaded = load_scene_files(scene);
  std::vector<EnvironmentMap> changed;
  for (const auto& r : recordings) {
    sim::synthesize_recording(r);
    changed.push_back(sim::changed_environment_map(loaded, *r.light_change));
  }

  std::map<int, double> errors, settled;
  for (int cols : kColumns)
    bench::register_measured_once(fmt::format("cells/{}", cols), [&, cols](benchmark::State& state) {
      double error = 0, ms = 0, settle = 0;
      for (std::size_t k = 0; k < recordings.size(); ++k) {
        pipeline::ReplayOverlaySettings rs;
        rs.poses = pipeline::PoseSource::Truth;
        rs.overlay.features = {false, false, false, false, false};
        rs.overlay.adapt_lighting_every = 2;
        rs.overlay.adapt_lighting_cells = cols;
        rs.overlay.volume_cache = false;
        const auto f =
            pipeline::follow_lighting_change(recordings[k].out, changed[k], recordings[k].light_change->at_s, rs);
        error += f.end_err / double(recordings.size());
        ms += f.adaptation_ms_per_frame / double(recordings.size());
        settle = std::max(settle, f.settled_after_s < 0 ? 99.0 : f.settled_after_s);
      }
      errors[cols] = error;
      settled[cols] = settle;
      state.counters["error_pct"] = 100 * error;
      state.counters["settled_s"] = settle;
      return ms;
    });

  bench::CollectingReporter reporter;
  bench::run_benchmarks(argc, argv, reporter);
  std::filesystem::remove_all(dir);

  bench::BenchReport report;
  report.name = "lighting_change_error_vs_time";
  report.title = "Following a lamp going out and a warmer window (label: map cells across)";
  report.baseline = "32";
  report.error_label = "figurine's irradiance vs the changed map's, last frame";
  for (int cols : kColumns)
    if (const auto* r = reporter.find(fmt::format("cells/{}", cols)))
      report.entries.push_back({fmt::format("{}", cols), r->time_ms, errors.at(cols)});
  report.highlight = "32";
  report.compute_ratios();
  std::string settle_text;
  for (const auto& [cols, s] : settled) settle_text += fmt::format(" {}: {:.2f} s;", cols, s);
  report.note = "ms: the lighting adaptation per frame. Within 5 % after the change (worst of the two):" + settle_text;
  report.publish(kColumns.size());
  fmt::print("{}\n", report.note);
  return 0;
}
