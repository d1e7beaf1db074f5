// Image-aided tracking (issue 17): the knobs of pipeline::ImageAidedPose against the
// registration error and the jitter at rest they give, and the time they cost per frame.
// The tracker's gain (PoseFusionSettings::tracker_gain: lower is steadier but slower to
// pull the video's drift back), the corners tracked (ImageAidedSettings::max_corners), and
// how often the frame is aligned with the room the proxy predicts for an absolute fix
// (ImageAidedSettings::align_every; PoseFusionSettings::fix_worth = 0 turns fixes off).
// Recordings, made here by lumar synth's code: the rest-then-turn (held 2 s, 30 deg/s for
// 1 s, held; jitter, lag, overshoot) and the orbit in a room unlike the proxy (a low
// table, a box, a cabinet, a wall 3 cm off). Error: the mean of the two recordings' mean
// registration error (pipeline::registration_error). Gain 1 is the tracker alone (the
// video is still tracked, so its time is the video's). The baseline of the ratios is the
// default setting.
// Writes bench/results/registration_error_vs_{jitter,time}.{json,png} and the same PNGs
// in docs/: the gain and corners against jitter, the fixes against time per frame.
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <unistd.h>

#include <map>

#include "bench_report.h"
#include "lumar/calib/camera_file.h"
#include "lumar/pipeline/registration_error.h"
#include "lumar/sim/synthetic_recording.h"

using namespace lumar;

namespace {

const std::filesystem::path kSource = LUMAR_SOURCE_DIR;

struct Setting {
  std::string name;
  double gain = 0.035;
  int corners = 300;
  int align_every = 24;
  double fix_worth = 400;
  bool fixes_chart = false;  // on the chart of the fixes (else on the gain's and corners')
};

const std::string kDefault = "default: gain 0.035, fix every 24";
const std::vector<Setting> kSettings{{kDefault},
                                     {"gain 0.01", 0.01},
                                     {"gain 0.02", 0.02},
                                     {"gain 0.07", 0.07},
                                     {"gain 0.15", 0.15},
                                     {"gain 0.3", 0.3},
                                     {"gain 1: tracker", 1.0, 300, 24, 0},
                                     {"corners 100", 0.035, 100},
                                     {"corners 600", 0.035, 600},
                                     {"no fixes", 0.035, 300, 24, 0, true},
                                     {"fix at start", 0.035, 300, 0, 400, true},
                                     {"fix every 48", 0.035, 300, 48, 400, true},
                                     {"fix every 12", 0.035, 300, 12, 400, true},
                                     {"fix every 6", 0.035, 300, 6, 400, true},
                                     {"fix every frame", 0.035, 300, 1, 400, true}};

struct Measured {
  double mean_px = 0, jitter_px = 0, lag_ms = 0, overshoot_px = 0, ms = 0;
};

}  // namespace

int main(int argc, char** argv) {
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("lumar-bench-registration-{}", ::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  sim::SynthSettings base;
  base.scene = kSource / "data/scenes/room/scene.json";
  base.camera = calib::load_camera_file(kSource / "data/camera/webcam-640x480.yml").intrinsics;
  base.supersample = 1;
  sim::SynthSettings turn = base, differs = base;
  turn.out = dir / "rest-turn", turn.path = "rest-turn", turn.frames = 108, turn.fps = 24;
  differs.out = dir / "room-differs", differs.room_differs = true;
  sim::synthesize_recording(turn);
  sim::synthesize_recording(differs);

  std::map<std::string, Measured> measured;
  for (const Setting& setting : kSettings)
    bench::register_measured_once(setting.name, [&, setting](benchmark::State& state) {
      pipeline::ReplayOverlaySettings rs;
      rs.image_aided.fusion.tracker_gain = setting.gain;
      rs.image_aided.max_corners = setting.corners;
      rs.image_aided.align_every = setting.align_every;
      rs.image_aided.fusion.fix_worth = setting.fix_worth;
      Measured m;
      for (const auto* r : {&turn, &differs}) {
        pipeline::ReplayOverlay overlay(r->out, rs);
        const auto e = pipeline::registration_error(overlay, pipeline::PoseSource::Fused);
        m.mean_px += e.mean / 2, m.ms += e.pose_ms / 2;
        if (r == &turn) m.jitter_px = e.jitter_px, m.lag_ms = e.lag_ms, m.overshoot_px = e.overshoot_px;
      }
      state.counters["mean_px"] = m.mean_px;
      state.counters["jitter_px"] = m.jitter_px;
      state.counters["lag_ms"] = m.lag_ms;
      state.counters["overshoot_px"] = m.overshoot_px;
      measured[setting.name] = m;
      return m.ms;
    });

  bench::CollectingReporter reporter;
  bench::run_benchmarks(argc, argv, reporter);
  std::filesystem::remove_all(dir);

  bench::BenchReport gains, fixes;
  gains.name = "registration_error_vs_jitter";
  gains.title = "Image-aided tracking: the tracker's gain and the corners tracked";
  gains.x_label = "jitter at rest (px RMS)";
  fixes.name = "registration_error_vs_time";
  fixes.title = "Image-aided tracking: how often the frame is aligned with the proxy's room";
  for (auto* report : {&gains, &fixes}) {
    report->baseline = report->highlight = kDefault;
    report->error_label = "mean registration error (px)";
  }
  for (const Setting& setting : kSettings)
    if (const auto* r = reporter.find(setting.name)) {
      const Measured& m = measured.at(setting.name);
      if (setting.fixes_chart || setting.name == kDefault)
        fixes.entries.push_back({setting.name, r->time_ms, m.mean_px});
      if (!setting.fixes_chart) gains.entries.push_back({setting.name, r->time_ms, m.mean_px, 0, m.jitter_px});
    }
  if (measured.count(kDefault)) {
    const Measured& m = measured.at(kDefault);
    gains.note = fixes.note =
        fmt::format("default: {:.1f} ms per frame, jitter {:.2f} px, lag {:.1f} ms, overshoot {:.2f} px", m.ms,
                    m.jitter_px, m.lag_ms, m.overshoot_px);
  }
  for (auto* report : {&gains, &fixes}) {
    report->compute_ratios();
    report->publish(report == &gains ? 9 : 7);
  }
  return 0;
}
