// Overlay at 640x480 on the sample recording: time per stage, and replay throughput.
// Baseline: decoding one video frame, measured in the same run.
#include <benchmark/benchmark.h>

#include "bench_report.h"
#include "lumar/calib/undistortion.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/render/compositor.h"
#include "lumar/render/platform/context.h"

using namespace lumar;

namespace {

struct Fixture {
  capture::RecordingReplay replay{std::filesystem::path(LUMAR_SOURCE_DIR) / "recordings/orbit"};
  std::unique_ptr<gl::Context> context = gl::create_headless_context();
  std::unique_ptr<Compositor> compositor;
  std::unique_ptr<capture::FrameSource> frames;
  capture::Frame frame;

  Fixture() {
    const auto maps = calib::make_undistortion_maps(replay.session().camera);
    compositor =
        std::make_unique<Compositor>(std::make_shared<const LoadedScene>(load_scene_files(replay.scene_path())),
                                     maps.output, maps.map_x, maps.map_y);
    frames = replay.open_frames();
  }
  // Next frame, starting over at the end.
  const capture::Frame& next() {
    if (!frames->read(frame)) {
      frames = replay.open_frames();
      frames->read(frame);
    }
    return frame;
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void decode_frame(benchmark::State& state) {
  auto& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(f.next().image.data);
}

void composite_frame(benchmark::State& state) {
  auto& f = fixture();
  const capture::Frame frame = f.next();
  const Pose pose = *f.replay.true_camera_pose(frame.index);
  gl::OverlayTimings sum;
  for (auto _ : state) {
    gl::OverlayTimings t;
    benchmark::DoNotOptimize(f.compositor->composite(frame.image, pose, 1.0, &t).data);
    sum.upload_ms += t.upload_ms, sum.background_ms += t.background_ms, sum.depth_ms += t.depth_ms;
    sum.objects_ms += t.objects_ms, sum.readback_ms += t.readback_ms;
  }
  using C = benchmark::Counter;
  state.counters["upload_ms"] = C(sum.upload_ms, C::kAvgIterations);
  state.counters["background_ms"] = C(sum.background_ms, C::kAvgIterations);
  state.counters["depth_ms"] = C(sum.depth_ms, C::kAvgIterations);
  state.counters["objects_ms"] = C(sum.objects_ms, C::kAvgIterations);
  state.counters["readback_ms"] = C(sum.readback_ms, C::kAvgIterations);
}

void replay_frame(benchmark::State& state) {
  auto& f = fixture();
  const double exposure = f.replay.session().radiometry.exposure;
  for (auto _ : state) {
    const capture::Frame& frame = f.next();
    const auto pose = f.replay.tracked_camera_pose(frame.time);
    if (pose) benchmark::DoNotOptimize(f.compositor->composite(frame.image, *pose, exposure).data);
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::RegisterBenchmark("decode_frame", decode_frame)
      ->Unit(benchmark::kMillisecond)
      ->MinTime(1.0)
      ->UseRealTime();
  benchmark::RegisterBenchmark("composite_frame", composite_frame)
      ->Unit(benchmark::kMillisecond)
      ->MinTime(2.0)
      ->UseRealTime();
  benchmark::RegisterBenchmark("replay_frame", replay_frame)
      ->Unit(benchmark::kMillisecond)
      ->MinTime(2.0)
      ->UseRealTime();
  benchmark::Initialize(&argc, argv);
  bench::CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  const auto* decode = reporter.find("decode_frame");
  const auto* composite = reporter.find("composite_frame");
  const auto* replay = reporter.find("replay_frame");
  if (!decode || !composite || !replay) return 0;  // a filtered run: no report
  const auto& c = composite->counters;
  bench::BenchReport report;
  report.name = "overlay_stages";
  report.title = "Overlay at 640x480, sample recording, Mesa llvmpipe: time per stage";
  report.baseline = "decode one video frame";
  report.entries = {
      {"decode one video frame", decode->time_ms},       {"upload frame", c.at("upload_ms")},
      {"background (undistort)", c.at("background_ms")}, {"proxy depth", c.at("depth_ms")},
      {"virtual objects (volume)", c.at("objects_ms")},  {"read back", c.at("readback_ms")},
      {"composite, all stages", composite->time_ms},     {"replay: decode+pose+composite", replay->time_ms}};
  report.compute_ratios();
  report.save(bench::results_dir());
  std::printf("replay throughput: %.1f frames/s\n", 1000.0 / replay->time_ms);
  return 0;
}
