// Shadow lines (issue 8): per-frame update of the figurine's shadow on the sample room's
// floor while the figurine moves, on ONE core, for several line counts with culling on
// and off (off: every line traced against the mesh), plus every line traced against the
// posed figurine as an Embree instance in world space (the earlier baseline), the culled
// update with the figurine jumping between frames (no help from the last frame), against the
// 2004 method (bounding sphere, thresholded emitters);
// each entry's error is the mean absolute attenuation error against brute-force ray
// integration where the reference is below 0.98. Also the precompute time (TBB, all cores).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <fmt/format.h>
#include <chrono>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <memory>

#include "bench_report.h"
#include "lumar/lighting/ray_scene.h"
#include "lumar/lighting/shadows/object_shadows.h"
#include "lumar/lighting/shadows/occluder_mesh.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/lighting/shadows/shadow_occlusion.h"
#include "lumar/scene/scene.h"

using namespace lumar;

namespace {

struct Setup {
  std::unique_ptr<ShadowScene> scene;
  Mesh receivers;
  glm::dmat4 base_pose{1.0};
  std::vector<glm::vec3> reference;  // attenuation at the error pose
};

Setup& setup() {
  static Setup s = [] {
    Setup out;
    Scene manifest = load_scene(std::filesystem::path(LUMAR_SOURCE_DIR) / "data/scenes/room/scene.json");
    manifest.shadows.receiver_vertices = 3400;
    out.base_pose = manifest.objects.at(0).T_world_model;
    out.scene = std::make_unique<ShadowScene>(load_scene_files(manifest));
    out.receivers = out.scene->receivers();
    return out;
  }();
  return s;
}

// The figurine's pose at frame k: gliding over the floor, turning, bobbing 5-25 cm up.
glm::dmat4 pose_at(int k) {
  const double t = 0.02 * k;
  const glm::dvec3 offset(-0.4 + 0.35 * std::cos(t), 0.15 + 0.1 * std::sin(1.7 * t), 0.4 + 0.35 * std::sin(t));
  return glm::translate(glm::dmat4(1.0), offset) * glm::rotate(glm::dmat4(1.0), 0.3 * t, glm::dvec3(0, 1, 0)) *
         glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 0)) * setup().base_pose;
}
glm::dmat4 error_pose() { return pose_at(0); }

EmitterOptions emitter_options(int samples) {
  EmitterOptions o;
  o.fixed_patches = 50;
  o.samples_per_patch = samples;
  return o;
}

struct Built {
  std::unique_ptr<LineShadows> shadows;
  double precompute_ms = 0;
  std::size_t lines = 0, candidates = 0;
};

Built build(int samples) {
  Setup& s = setup();
  const auto t0 = std::chrono::steady_clock::now();
  const Emitters e = s.scene->emitters(s.receivers.positions, s.receivers.normals, emitter_options(samples));
  ShadowLines lines = build_shadow_lines(s.receivers.positions, s.receivers.normals, e, s.scene->proxy());
  Built b;
  b.precompute_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  b.lines = lines.lines.size();
  b.candidates = lines.candidate_lines;
  b.shadows = std::make_unique<LineShadows>(std::move(lines));
  b.shadows->add_object(s.scene->objects().at(0).model, error_pose());
  return b;
}

// Frame after frame of the figurine moving (`stride` frames of pose_at apart), the
// per-frame update of `b` timed, with its counters.
void run_frames(benchmark::State& state, Built& b, bool cull, int stride) {
  tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
  b.shadows->set_culling(cull);
  int frame = 1;
  std::size_t candidates = 0, tested = 0, blocked = 0, rows = 0, walked = 0;
  double cull_ms = 0, trace_ms = 0;
  for (auto _ : state) {
    b.shadows->set_object_pose(0, pose_at(stride * frame++));
    b.shadows->update();
    const ShadowFrameStats& st = b.shadows->stats();
    candidates += st.rays_traced, tested += st.receivers_tested, blocked += st.lines_blocked;
    walked += st.lines_walked, rows += st.rows_scanned;
    cull_ms += st.cull_ms, trace_ms += st.trace_ms;
  }
  const double n = double(state.iterations());
  state.counters["cull_ms"] = cull_ms / n;
  state.counters["trace_ms"] = trace_ms / n;
  state.counters["rays"] = double(candidates) / n;
  state.counters["tested"] = double(tested) / n;
  state.counters["blocked"] = double(blocked) / n;
  state.counters["rows"] = double(rows) / n;
  state.counters["walked"] = double(walked) / n;
}

double error_of(const std::vector<glm::vec3>& a) {
  const auto& ref = setup().reference;
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (ref[i][c] < 0.98) sum += std::abs(a[i][c] - ref[i][c]), ++n;
  return n ? sum / double(n) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  Setup& s = setup();
  const auto& fig = s.scene->objects().at(0);
  const bool quick = std::getenv("LUMAR_SHADOW_BENCH_QUICK") != nullptr;
  if (quick)
    s.reference.assign(s.receivers.positions.size(), glm::vec3(1.0f));
  else {
    std::vector<ShadowScene::Object> objects{{fig.name, fig.model, error_pose(), glm::vec3(0.8f), {}}};
    EnvironmentMap map = s.scene->map();
    const ShadowScene posed(std::move(map), false, s.scene->room(), std::move(objects));
    s.reference = shadow_attenuation(posed, s.receivers.positions, s.receivers.normals, ShadowMethod::Reference);
  }
  fmt::print("{} receivers; reference computed\n", s.receivers.positions.size());

  const std::vector<int> samples = {1, 2, 4, 8};
  std::map<int, Built> built;
  std::map<std::string, double> errors;
  std::map<std::string, std::size_t> line_counts;
  for (int k : samples) {
    built[k] = build(k);
    Built& b = built[k];
    b.shadows->set_object_pose(0, error_pose());
    b.shadows->update();
    const double err = error_of(b.shadows->attenuation());
    for (bool cull : {true, false}) {
      const std::string name = fmt::format("lines/{}/{}", k, cull ? "culled" : "all");
      errors[name] = err;
      line_counts[name] = b.lines;
      benchmark::RegisterBenchmark(name.c_str(), [&b, cull](benchmark::State& state) { run_frames(state, b, cull, 1); })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(1.0);
    }
  }
  // The same, the figurine jumping ~0.3 m between frames: last frame's blockers no
  // longer help (the worst case of the walk). In the note, not the chart.
  benchmark::RegisterBenchmark("lines/8/culled_jumping",
                               [&](benchmark::State& state) { run_frames(state, built.at(8), true, 40); })
      ->Unit(benchmark::kMillisecond)
      ->MinTime(1.0);

  // Every line against the posed figurine as an Embree instance (world space, one ray
  // stream): the baseline as measured before the model-space one. In the note, not the
  // chart (its label would sit on the model-space one's).
  benchmark::RegisterBenchmark("lines/8/instanced",
                               [&](benchmark::State& state) {
                                 tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
                                 const ShadowLines& lines = built.at(8).shadows->lines();
                                 RayScene scene;
                                 const int id = scene.add_instance(fig.model, error_pose());
                                 std::vector<Ray> rays(lines.lines.size());
                                 std::vector<std::uint8_t> blocked(rays.size());
                                 const float t_far = shadow_ray_t_far(lines.distant);
                                 int frame = 1;
                                 std::size_t count = 0;
                                 for (auto _ : state) {
                                   scene.set_instance_transform(id, pose_at(frame++));
                                   scene.commit();
                                   for (std::size_t li = 0; li < rays.size(); ++li) {
                                     const ShadowLine& l = lines.lines[li];
                                     const glm::vec3 from = lines.origins[l.receiver];
                                     rays[li] = Ray{from, 0.0f, lines.line_end(l) - from, t_far};
                                   }
                                   scene.occluded(rays, blocked, true);
                                   for (const std::uint8_t b : blocked) count += b;
                                 }
                                 state.counters["blocked"] = double(count) / double(state.iterations());
                               })
      ->Unit(benchmark::kMillisecond)
      ->MinTime(1.0);

  // Embree's cost for the blocked lines alone: only the lines that ARE blocked at each
  // pose (known from tracing every line beforehand), traced one by one as the culled
  // method traces the candidates it cannot prove blocked by a walk. With Embree alone,
  // no culling could get below this; the ratio target needs 1/20 of "all".
  benchmark::RegisterBenchmark("lines/8/blocked_only",
                               [&](benchmark::State& state) {
                                 tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
                                 const ShadowLines& lines = built.at(8).shadows->lines();
                                 LineShadows oracle(lines);
                                 oracle.add_object(fig.model, error_pose());
                                 oracle.set_culling(false);
                                 const OccluderMesh mesh(fig.model);
                                 const float t_far = shadow_ray_t_far(lines.distant);
                                 constexpr int kPoses = 16;
                                 std::vector<glm::mat4> model_from_world;
                                 std::vector<std::vector<std::uint32_t>> blocked;
                                 for (int k = 1; k <= kPoses; ++k) {
                                   oracle.set_object_pose(0, pose_at(k));
                                   oracle.update();
                                   blocked.push_back(oracle.blocked_lines());
                                   model_from_world.push_back(glm::mat4(glm::inverse(pose_at(k))));
                                 }
                                 int frame = 0;
                                 std::size_t count = 0;
                                 for (auto _ : state) {
                                   const int k = frame++ % kPoses;
                                   const glm::mat4& M = model_from_world[std::size_t(k)];
                                   for (const std::uint32_t li : blocked[std::size_t(k)]) {
                                     const ShadowLine& l = lines.lines[li];
                                     const glm::vec3 a = glm::vec3(M * glm::vec4(lines.origins[l.receiver], 1.0f));
                                     const glm::vec3 b = glm::vec3(M * glm::vec4(lines.line_end(l), 1.0f));
                                     count += mesh.occluded(a, b - a, t_far);
                                   }
                                 }
                                 state.counters["blocked"] = double(count) / double(state.iterations());
                               })
      ->Unit(benchmark::kMillisecond)
      ->MinTime(1.0);

  // Objects shadowing each other: two figurines side by side (about 0.15 m apart), one
  // moving a centimetre per frame, with the default emitter samples and with fewer.
  std::map<int, std::size_t> object_samples;
  for (const int per_patch : {8, 2}) {
    const std::string name = fmt::format("objects/{}", per_patch);
    benchmark::RegisterBenchmark(name.c_str(),
                                 [&, per_patch](benchmark::State& state) {
                                   tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
                                   const Mesh posed = transformed(fig.model, error_pose());
                                   EmitterOptions options;
                                   options.samples_per_patch = per_patch;
                                   const Emitters emitters = s.scene->emitters(posed.positions, posed.normals, options);
                                   object_samples[per_patch] = emitters.samples.size();
                                   ObjectShadows shadows(emitters);
                                   shadows.add_object(fig.model, error_pose());
                                   const glm::dmat4 beside = glm::translate(glm::dmat4(1.0), glm::dvec3(0.6, 0, 0.05));
                                   const int b = shadows.add_object(fig.model, beside * error_pose());
                                   int frame = 0;
                                   std::size_t shadowed = 0, rays = 0, blocked = 0, walked = 0;
                                   for (auto _ : state) {
                                     const glm::dvec3 step(0.01 * (frame++ % 6 + 1), 0, 0);
                                     shadows.set_object_pose(
                                         b, glm::translate(glm::dmat4(1.0), step) * beside * error_pose());
                                     shadows.update();
                                     shadowed += shadows.stats().vertices_shadowed, rays += shadows.stats().rays_traced;
                                     blocked += shadows.stats().lines_blocked, walked += shadows.stats().lines_walked;
                                   }
                                   state.counters["vertices_shadowed"] = double(shadowed) / double(state.iterations());
                                   state.counters["rays"] = double(rays) / double(state.iterations());
                                   state.counters["blocked"] = double(blocked) / double(state.iterations());
                                   state.counters["walked"] = double(walked) / double(state.iterations());
                                 })
        ->Unit(benchmark::kMillisecond)
        ->MinTime(1.0);
  }

  // The 2004 method per frame: every line against the bounding sphere.
  const Emitters thresholded =
      s.scene->emitters(s.receivers.positions, s.receivers.normals, sphere_baseline_emitter_options());
  {
    const std::vector<BoundingSphere> spheres{bounding_sphere(fig.model, error_pose())};
    errors["sphere"] = error_of(
        sphere_attenuation(s.receivers.positions, s.receivers.normals, thresholded, s.scene->proxy(), spheres));
  }
  benchmark::RegisterBenchmark(
      "sphere",
      [&](benchmark::State& state) {
        tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
        int frame = 1;
        for (auto _ : state) {
          const std::vector<BoundingSphere> spheres{bounding_sphere(fig.model, pose_at(frame++))};
          benchmark::DoNotOptimize(
              sphere_attenuation(s.receivers.positions, s.receivers.normals, thresholded, s.scene->proxy(), spheres));
        }
      })
      ->Unit(benchmark::kMillisecond)
      ->MinTime(1.0);

  benchmark::Initialize(&argc, argv);
  bench::CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  bench::BenchReport report;
  report.name = "shadow_error_vs_time";
  report.title =
      fmt::format("Moving figurine's shadow, {} receivers x 50 patches, one core", s.receivers.positions.size());
  report.baseline = "2004 sphere";
  report.error_label = "mean |attenuation - reference| where reference < 0.98";
  for (const auto& [key, err] : errors) {
    const auto* r = reporter.find(key);
    if (!r) continue;
    std::string name = key == "sphere" ? "2004 sphere"
                                       : fmt::format("{}k lines, {}", line_counts[key] / 1000,
                                                     key.ends_with("culled") ? "culled" : "all traced");
    report.entries.push_back({name, r->time_ms, err});
  }
  report.compute_ratios();

  const Built& big = built.at(8);
  const auto* culled = reporter.find("lines/8/culled");
  const auto* all = reporter.find("lines/8/all");
  const auto* instanced = reporter.find("lines/8/instanced");
  const auto* blocked_only = reporter.find("lines/8/blocked_only");
  const auto* jumping = reporter.find("lines/8/culled_jumping");
  const double speedup = culled && all ? all->time_ms / culled->time_ms : 0.0;
  const double speedup_instanced = culled && instanced ? instanced->time_ms / culled->time_ms : 0.0;
  report.note = fmt::format(
      "{} lines (8 per pair): {:.2f} ms/frame culled, {:.1f} ms all traced ({:.1f}x), {:.1f} ms all traced "
      "as a world-space instance ({:.1f}x), culled with the figurine jumping {:.2f} ms; precompute {}x50 (1 "
      "line/pair) {:.0f} ms, 8 lines/pair {:.0f} ms",
      big.lines, culled ? culled->time_ms : 0.0, all ? all->time_ms : 0.0, speedup,
      instanced ? instanced->time_ms : 0.0, speedup_instanced, jumping ? jumping->time_ms : 0.0,
      s.receivers.positions.size(), built.at(1).precompute_ms, big.precompute_ms);
  if (quick) {
    fmt::print("LUMAR_SHADOW_BENCH_QUICK: no reference, so the chart and JSON are left as they are\n");
  } else {
    report.publish(errors.size());  // the chart also lives beside the shadow docs
  }
  fmt::print("{}\n", report.note);
  for (int k : samples)
    fmt::print("samples/patch {}: {} lines kept of {} candidates, precompute {:.0f} ms, error {:.4f}\n", k,
               built[k].lines, built[k].candidates, built[k].precompute_ms, errors[fmt::format("lines/{}/culled", k)]);
  fmt::print("2004 sphere error {:.4f}\n", errors["sphere"]);
  if (blocked_only)
    fmt::print(
        "tracing only the lines that are blocked with Embree: {:.2f} ms per frame, {:.1f}x faster than all "
        "traced\n",
        blocked_only->time_ms, all ? all->time_ms / blocked_only->time_ms : 0.0);
  for (const int per_patch : {8, 2})
    if (const auto* r = reporter.find(fmt::format("objects/{}", per_patch)))
      fmt::print("two figurines shadowing each other ({} vertices each, {} emitter samples): {:.1f} ms per update\n",
                 fig.model.positions.size(), object_samples[per_patch], r->time_ms);
  return 0;
}
