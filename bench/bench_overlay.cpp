// Overlay at 640x480 on the sample recording, through the pipeline library that `lumar
// overlay` runs (pipeline/replay_overlay.h: the session's radiometry, the tracker's poses):
// time per stage, and replay throughput. Baseline: decoding one video frame, measured in
// the same run. The composite is timed with every feature that makes it look like the
// camera's pixels (antialiasing, self-occlusion, noise, blur, contact shadows:
// docs/ground_truth.md), with all but the contact shadows, and with them all off, so that
// their cost is a ratio from the same run. The walk
// recording adds moving objects: the figurine walks across the floor beside a second
// one, so its shadow on the floor and on the other object is traced again every frame.
// Throughput: both recordings replayed whole as `lumar overlay` does, today's serial path
// with per-pixel shading (the baseline of that table) against the pipelined stages with
// per-vertex shading (ReplayOverlay::run, ObjectShading), without output and with H.264.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <map>

#include "bench_report.h"
#include "lumar/pipeline/output_files.h"
#include "lumar/pipeline/replay_overlay.h"

using namespace lumar;

namespace {

const std::filesystem::path kRecording = std::filesystem::path(LUMAR_SOURCE_DIR) / "recordings/orbit";
const std::filesystem::path kWalk = std::filesystem::path(LUMAR_SOURCE_DIR) / "recordings/walk";

// Which of the features that make the composite look real are on (the shadow lines and
// the bounce stay on in all three).
enum class Look { All, NoContact, Off };

pipeline::ReplayOverlaySettings with_look(Look look) {
  pipeline::ReplayOverlaySettings s;
  gl::CompositeFeatures& f = s.overlay.features;
  f.contact = look == Look::All;
  if (look == Look::Off) f.antialiasing = f.self_occlusion = f.noise = f.blur = false;
  return s;
}

struct Fixture {
  explicit Fixture(Look look) : overlay(kRecording, with_look(look)) {}
  pipeline::ReplayOverlay overlay;
  std::unique_ptr<capture::FrameSource> frames = overlay.replay().open_frames();
  capture::Frame frame;

  // Next frame, starting over at the end.
  const capture::Frame& next() {
    if (!frames->read(frame)) {
      frames = overlay.replay().open_frames();
      frames->read(frame);
    }
    return frame;
  }
};

Fixture& fixture(Look look = Look::All) {
  static std::map<Look, std::unique_ptr<Fixture>> fixtures;
  auto& f = fixtures[look];
  if (!f) f = std::make_unique<Fixture>(look);
  return *f;
}

void decode_frame(benchmark::State& state) {
  auto& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(f.next().image.data);
}

// One frame again and again: the rendering stages alone.
void composite_frame(benchmark::State& state) {
  auto& f = fixture();
  const capture::Frame frame = f.next();
  const auto pose = f.overlay.replay().tracked_camera_pose(frame.time);
  pipeline::Overlay& overlay = f.overlay.overlay();
  overlay.composite(frame, pose);  // outside the clock: the first builds the contact shadows
  const pipeline::StageTimes before = overlay.times();
  for (auto _ : state) benchmark::DoNotOptimize(overlay.composite(frame, pose).composite.data);
  const pipeline::StageTimes& after = overlay.times();
  using C = benchmark::Counter;
  state.counters["upload_ms"] = C(after.upload - before.upload, C::kAvgIterations);
  state.counters["background_ms"] = C(after.background - before.background, C::kAvgIterations);
  state.counters["depth_ms"] = C(after.depth - before.depth, C::kAvgIterations);
  state.counters["objects_ms"] = C(after.objects - before.objects, C::kAvgIterations);
  state.counters["antialiasing_ms"] = C(after.antialiasing - before.antialiasing, C::kAvgIterations);
  state.counters["blur_ms"] = C(after.blur - before.blur, C::kAvgIterations);
  state.counters["readback_ms"] = C(after.readback - before.readback, C::kAvgIterations);
}

// The look-real features' cost: the same frame composited with all of them, without the
// contact shadows and with none, in turn within each iteration (the order rotating), so
// that the machine's drift during the run falls on all three alike.
void look_costs(benchmark::State& state) {
  const std::array<Look, 3> looks{Look::All, Look::NoContact, Look::Off};
  std::array<capture::Frame, 3> frames;
  std::array<std::optional<Pose>, 3> poses;
  for (int i = 0; i < 3; ++i) {
    Fixture& f = fixture(looks[i]);
    frames[i] = f.next();
    poses[i] = f.overlay.replay().tracked_camera_pose(frames[i].time);
    f.overlay.overlay().composite(frames[i], poses[i]);  // the first builds the contact shadows
  }
  std::array<double, 3> ms{};
  int start = 0;
  for (auto _ : state) {
    for (int k = 0; k < 3; ++k) {
      const int i = (start + k) % 3;
      const auto t0 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(fixture(looks[i]).overlay.overlay().composite(frames[i], poses[i]).composite.data);
      ms[i] += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
    start = (start + 1) % 3;
  }
  using C = benchmark::Counter;
  state.counters["all_ms"] = C(ms[0], C::kAvgIterations);
  state.counters["without_contact_ms"] = C(ms[1], C::kAvgIterations);
  state.counters["off_ms"] = C(ms[2], C::kAvgIterations);
}

// The quality knobs of a replay: full quality per pixel, the same per vertex, or what
// `--quality auto` chooses on the recording (pipeline/quality_choice.h).
enum class Knobs { PerPixel, PerVertex, Auto };

// How one replay is run: which recording, knobs and threads, and whether H.264 is written.
struct Throughput {
  bool walk = false;
  Knobs knobs = Knobs::PerPixel;
  bool pipelined = false, encode = false;
  std::string label() const {  // within one recording's table
    return std::string(pipelined ? "pipelined" : "serial") +
           (knobs == Knobs::PerPixel    ? ", per pixel"
            : knobs == Knobs::PerVertex ? ", per vertex"
                                        : ", auto") +
           (encode ? ", H.264" : "");
  }
  std::string name() const { return std::string(walk ? "walk, " : "orbit, ") + label(); }
};

// One overlay per recording and knobs, made (its shaders compiled, auto's choice made)
// before a clock runs; its stage times add up over every replay of it.
pipeline::ReplayOverlay& throughput_overlay(bool walk, Knobs knobs) {
  static std::map<std::pair<bool, Knobs>, std::unique_ptr<pipeline::ReplayOverlay>> overlays;
  auto& overlay = overlays[{walk, knobs}];
  if (!overlay) {
    pipeline::ReplayOverlaySettings s;
    s.overlay.quality.shading = knobs == Knobs::PerVertex ? ObjectShading::PerVertex : ObjectShading::PerPixel;
    if (knobs == Knobs::Auto) s.auto_quality = pipeline::QualityBudget{};
    overlay = std::make_unique<pipeline::ReplayOverlay>(walk ? kWalk : kRecording, s);
    overlay->run(2, [](const pipeline::OverlayFrame&) { return true; });
  }
  return *overlay;
}

// Frames per second and latency over whole replays, through the pipeline library.
void replay_throughput(benchmark::State& state, Throughput t) {
  pipeline::ReplayOverlay& overlay = throughput_overlay(t.walk, t.knobs);
  const auto& camera = overlay.compositor().output_camera();
  const std::string video =
      (std::filesystem::temp_directory_path() / ("lumar-bench-" + std::to_string(::getpid()) + ".mp4")).string();
  const pipeline::StageTimes before = overlay.times();
  for (auto _ : state) {
    std::optional<pipeline::OverlayOutputs> outputs;
    if (t.encode)
      outputs.emplace(pipeline::OverlayOutputSettings{video, "", "", overlay.replay().reader().video().fps,
                                                      cv::Size(camera.width, camera.height)});
    overlay.run(
        0,
        [&](const pipeline::OverlayFrame& f) {
          if (outputs) outputs->write(f.index, f.composite);
          benchmark::DoNotOptimize(f.composite.data);
          return true;
        },
        t.pipelined);
    if (outputs) outputs->commit();
  }
  std::filesystem::remove(video);
  const pipeline::StageTimes& after = overlay.times();
  const double frames = after.frames - before.frames;
  using C = benchmark::Counter;
  state.counters["frames"] = C(frames, C::kAvgIterations);  // per pass
  state.counters["latency_ms"] = C((after.latency - before.latency) / std::max(1.0, frames));
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
  benchmark::RegisterBenchmark("look_costs", look_costs)->Unit(benchmark::kMillisecond)->MinTime(6.0)->UseRealTime();
  std::vector<Throughput> throughputs;
  for (bool walk : {false, true})
    for (const Throughput& t :
         {Throughput{walk, Knobs::PerPixel, false, false}, Throughput{walk, Knobs::PerVertex, false, false},
          Throughput{walk, Knobs::PerVertex, true, false}, Throughput{walk, Knobs::Auto, true, false},
          Throughput{walk, Knobs::PerPixel, false, true}, Throughput{walk, Knobs::PerVertex, true, true},
          Throughput{walk, Knobs::Auto, true, true}})
      throughputs.push_back(t);
  for (const Throughput& t : throughputs)
    benchmark::RegisterBenchmark(("throughput/" + t.name()).c_str(), replay_throughput, t)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(2)
        ->UseRealTime();
  benchmark::Initialize(&argc, argv);
  bench::CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  const auto* decode = reporter.find("decode_frame");
  const auto* composite = reporter.find("composite_frame");
  const auto* looks = reporter.find("look_costs");
  if (!decode || !composite || !looks) return 0;  // a filtered run: no report
  const double all_ms = looks->counters.at("all_ms"), no_contact_ms = looks->counters.at("without_contact_ms"),
               off_ms = looks->counters.at("off_ms");
  // A replay's time per frame (nullopt: not run).
  const auto ms_per_frame = [&](const Throughput& t) -> std::optional<double> {
    const auto* r = reporter.find("throughput/" + t.name());
    if (!r) return std::nullopt;
    return r->time_ms / std::max(1.0, r->counters.at("frames"));
  };
  const auto replay = ms_per_frame(Throughput{}), walk = ms_per_frame(Throughput{.walk = true});
  if (!replay || !walk) return 0;
  const double replay_ms = *replay, walk_ms = *walk;
  const auto& c = composite->counters;
  bench::BenchReport report;
  report.name = "overlay_stages";
  report.title = "Overlay at 640x480, sample recording, Mesa llvmpipe: time per stage";
  report.baseline = "decode one video frame";
  report.entries = {{"decode one video frame", decode->time_ms},
                    {"upload frame", c.at("upload_ms")},
                    {"background (undistort)", c.at("background_ms")},
                    {"proxy depth", c.at("depth_ms")},
                    {"virtual objects (volume)", c.at("objects_ms")},
                    {"antialiasing", c.at("antialiasing_ms")},
                    {"camera blur", c.at("blur_ms")},
                    {"read back", c.at("readback_ms")},
                    {"composite, all stages", composite->time_ms},
                    {"look-real features on (in turn)", all_ms},
                    {"  ... without contact shadows", no_contact_ms},
                    {"  ... all of them off", off_ms},
                    {"replay: decode+pose+composite", replay_ms}};
  // The walk shaded per pixel: per stage, over its replays (the overlay's own stage clock).
  const pipeline::StageTimes& w = throughput_overlay(true, Knobs::PerPixel).times();
  const double walk_frames = std::max(1, w.frames);
  for (const auto& [name, ms] : std::initializer_list<std::pair<const char*, double>>{
           {"walk: decode video", w.decode},
           {"walk: shadows (moved objects)", w.shadows},
           {"walk: virtual objects", w.objects},
           {"walk: other rendering stages", w.upload + w.background + w.depth + w.antialiasing + w.blur + w.readback}})
    report.entries.push_back({name, ms / walk_frames});
  report.entries.push_back({"walk: replay, all stages", walk_ms});
  report.compute_ratios();
  report.save(bench::results_dir());

  // Throughput per recording, against today's serial per-pixel path in the same run.
  for (bool walk : {false, true}) {
    bench::BenchReport table;
    table.name = walk ? "overlay_throughput_walk" : "overlay_throughput";
    table.title = std::string("Replay throughput at 640x480, ") + (walk ? "walk (moving objects)" : "sample orbit") +
                  ", Mesa llvmpipe: ms per frame";
    for (const Throughput& t : throughputs) {
      if (t.walk != walk) continue;
      const auto ms = ms_per_frame(t);
      if (!ms) return 0;
      table.entries.push_back({t.label(), *ms});
      std::printf("%-40s %6.2f ms per frame  %5.1f frames/s  latency %6.1f ms\n", t.name().c_str(), *ms, 1000.0 / *ms,
                  reporter.find("throughput/" + t.name())->counters.at("latency_ms"));
    }
    table.baseline = table.entries.front().name;
    table.compute_ratios();
    table.save(bench::results_dir());
    if (const auto& choice = throughput_overlay(walk, Knobs::Auto).quality_choice())
      std::printf("%s: auto chose %s (%.1f ms per frame in its trials against full quality's %.1f)\n",
                  walk ? "walk" : "orbit", choice->choice().quality.describe().c_str(), choice->choice().ms_per_frame,
                  choice->full().ms_per_frame);
  }
  std::printf("replay throughput: %.1f frames/s\n", 1000.0 / replay_ms);
  std::printf(
      "moving figurine with its shadow and a second object (walk): %.1f frames/s, %.2f ms per frame of which %.2f ms "
      "shadows; the 2004 system: 0.8-0.9 frames/s with moving shadows\n",
      1000.0 / walk_ms, walk_ms, w.shadows / walk_frames);
  std::printf(
      "antialiasing, self-occlusion, noise, blur and contact shadows: %+.2f ms per 640x480 frame (composite %.2f ms, "
      "%.3f x the %.2f ms with them off); contact shadows alone: %+.2f ms (%.3f x)\n",
      all_ms - off_ms, all_ms, all_ms / off_ms, off_ms, all_ms - no_contact_ms, all_ms / no_contact_ms);
  return 0;
}
