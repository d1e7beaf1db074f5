// Bounce (issue 18): the light a moving virtual object reflects onto the real floor, per
// frame on ONE core, against the number of surface clusters per object (the knob). The
// error is against the composite's ground truth (composite_reference.h: brute force with
// Embree, the bounce as the difference of the truth with and without it), relative to the
// bounce's own size: Σ|bounce − reference| / Σ reference over the floor's receivers and
// the three channels. Case: a saturated red box (25 cm, albedo 0.9/0.05/0.05) on the sample
// room's floor, 5 cm from a wall. Also the per-frame cost of the figurine's bounce while it
// glides over the sample floor (3200 receivers), the overlay's case.
// Writes bench/results/bounce_error_vs_time.{json,png} and docs/bounce_error_vs_time.png.
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <tbb/global_control.h>

#include <chrono>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <memory>

#include "bench_report.h"
#include "lumar/lighting/composite_reference.h"
#include "lumar/lighting/irradiance_scene.h"
#include "lumar/lighting/self_occlusion.h"
#include "lumar/lighting/shadows/object_bounce.h"
#include "lumar/lighting/shadows/shadow_lines.h"
#include "lumar/lighting/shadows/shadow_methods.h"
#include "lumar/scene/scene.h"

using namespace lumar;

namespace {

const std::filesystem::path kSource = LUMAR_SOURCE_DIR;

glm::dmat4 translation(double x, double y, double z) { return glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z)); }

// One case: a scene with one object, its floor receivers and their lines' E_without, the
// volume that shades the object.
struct Case {
  std::unique_ptr<ShadowScene> scene;
  Mesh receivers;
  ShadowLines lines;
  std::shared_ptr<IrradianceVolume> volume;
  std::vector<VertexOcclusion> occlusion;

  ObjectBounce::Irradiance irradiance() const {
    return [v = volume.get()](const glm::vec3& p, const glm::vec3& n) {
      return glm::vec3(v->evaluate(glm::dvec3(p), glm::dvec3(n)));
    };
  }
  std::unique_ptr<ObjectBounce> bounce(int clusters) const {
    BounceSettings settings;
    settings.clusters = clusters;
    auto b = std::make_unique<ObjectBounce>(lines.origins, receivers.normals, lines.unshadowed, settings);
    const LoadedObject& o = scene->objects().at(0);
    b->add_object(o.model, o.albedo, o.T_world_model);
    b->set_object_occlusion(0, occlusion);
    return b;
  }
};

Case make_case(Scene manifest, LoadedObject object) {
  Case c;
  manifest.objects.clear();
  LoadedScene loaded = load_scene_files(manifest);
  loaded.objects.push_back(std::move(object));
  c.scene = std::make_unique<ShadowScene>(std::move(loaded));
  c.receivers = c.scene->receivers();
  const Emitters e = c.scene->emitters(c.receivers.positions, c.receivers.normals);
  c.lines = build_shadow_lines(c.receivers.positions, c.receivers.normals, e, c.scene->proxy());
  c.volume = std::make_shared<IrradianceVolume>(scene_irradiance_volume(c.scene->scene(), "volume"));
  c.occlusion = bake_self_occlusion(c.scene->objects().at(0).model);
  return c;
}

// The red box in the corner: the volume and the receivers cover the corner.
Case red_box_case() {
  Scene manifest = load_scene(kSource / "data/scenes/room/scene.json");
  manifest.movement_min = {-2.99, 0.0, -0.7};
  manifest.movement_max = {-1.6, 1.0, 0.9};
  manifest.shadows.receivers = {SceneBox{{-3.0, -0.1, -0.7}, {-1.9, 0.1, 0.9}}};
  LoadedObject box;
  box.name = "red box";
  box.model = load_mesh(kSource / "data/models/box.obj");
  box.T_world_model = translation(-2.825, 0.0, 0.1);  // 5 cm from the wall at x = -3
  box.albedo = {0.9f, 0.05f, 0.05f};
  return make_case(manifest, box);
}

Case figurine_case() {
  const Scene manifest = load_scene(kSource / "data/scenes/room/scene.json");
  return make_case(manifest, load_scene_files(manifest).objects.at(0));
}

// The reference's bounce over the case's receivers (converged: 16² rays per cone).
std::vector<glm::vec3> reference_bounce(const Case& c) {
  const std::unique_ptr<RoomRadiance> radiance = scene_radiance(c.scene->scene(), RadianceSettings{});
  CompositeReferenceSettings settings;
  settings.cone_strata = 16;
  const CompositeReference with(*radiance, c.scene->objects(), settings);
  settings.bounce = false;
  const CompositeReference without(*radiance, c.scene->objects(), settings);
  std::vector<glm::vec3> out(c.receivers.positions.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const glm::dvec3 p(c.receivers.positions[i]), n(c.receivers.normals[i]);
    out[i] = glm::vec3(with.room_ratio(p, n) - without.room_ratio(p, n));
  }
  return out;
}

// Over the receivers not under the object (a point under the box sees its inside, which no
// camera sees; the reference's rays there meet the box's faces from within).
double relative_error(const Case& c, const std::vector<glm::vec3>& bounce, const std::vector<glm::vec3>& reference) {
  const Mesh posed = transformed(c.scene->objects().at(0).model, c.scene->objects().at(0).T_world_model);
  const auto [lo, hi] = posed.bounds();
  double error = 0, size = 0;
  for (std::size_t i = 0; i < bounce.size(); ++i) {
    const glm::vec3 p = c.receivers.positions[i];
    if (p.x > lo.x - 0.01f && p.x < hi.x + 0.01f && p.z > lo.z - 0.01f && p.z < hi.z + 0.01f) continue;
    for (int k = 0; k < 3; ++k) error += std::abs(bounce[i][k] - reference[i][k]), size += reference[i][k];
  }
  return size > 0 ? error / size : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  const Case box = red_box_case();
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<glm::vec3> reference = reference_bounce(box);
  const double reference_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  fmt::print("reference bounce over {} receivers: {:.0f} ms (all cores)\n", box.receivers.positions.size(),
             reference_ms);

  const std::vector<int> cluster_counts = {8, 16, 32, 64, 128, 256, 512, 1024};
  std::map<std::string, double> errors;
  for (int k : cluster_counts) {
    const auto b = box.bounce(k);
    b->update(box.irradiance());
    const std::string name = fmt::format("box/{}", k);
    errors[name] = relative_error(box, b->ratio(), reference);
    benchmark::RegisterBenchmark(
        name.c_str(),
        [&box, k](benchmark::State& state) {
          tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
          const auto b = box.bounce(k);
          int frame = 0;
          for (auto _ : state) {
            // A new pose every frame: the box slides along the wall, a millimetre at a time.
            b->set_object_pose(0, translation(0, 0, 0.001 * (frame++ % 50)) * box.scene->objects()[0].T_world_model);
            b->update(box.irradiance());
          }
          state.counters["pairs"] = double(b->stats().pairs);
          state.counters["near_pairs"] = double(b->stats().near_pairs);
        })
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.5);
  }
  const Case figurine = figurine_case();
  benchmark::RegisterBenchmark(
      "figurine",
      [&figurine](benchmark::State& state) {
        tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
        const auto b = figurine.bounce(BounceSettings{}.clusters);
        int frame = 0;
        for (auto _ : state) {
          b->set_object_pose(0, translation(0.002 * (frame++ % 50), 0, 0) * figurine.scene->objects()[0].T_world_model);
          b->update(figurine.irradiance());
        }
        state.counters["pairs"] = double(b->stats().pairs);
        state.counters["near_pairs"] = double(b->stats().near_pairs);
      })
      ->Unit(benchmark::kMillisecond)
      ->MinTime(0.5);

  benchmark::Initialize(&argc, argv);
  bench::CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  bench::BenchReport report;
  report.name = "bounce_error_vs_time";
  report.title = fmt::format("Red box's bounce on the floor, {} receivers, one core (label: clusters)",
                             box.receivers.positions.size());
  report.baseline = "reference";
  report.error_label = "sum |bounce - reference| / sum reference";
  // The reference's error is 0 by definition: not drawn on the log chart.
  report.entries.push_back({"reference", reference_ms, std::numeric_limits<double>::quiet_NaN()});
  for (int k : cluster_counts) {
    const auto* r = reporter.find(fmt::format("box/{}", k));
    if (r) report.entries.push_back({fmt::format("{}", k), r->time_ms, errors.at(fmt::format("box/{}", k))});
  }
  report.highlight = fmt::format("{}", BounceSettings{}.clusters);
  report.compute_ratios();
  const auto* fig = reporter.find("figurine");
  const auto* def = reporter.find(fmt::format("box/{}", BounceSettings{}.clusters));
  report.note = fmt::format(
      "default {} clusters: box {:.2f} ms/frame, error {:.3f}; the figurine gliding over the sample floor: {:.2f} "
      "ms/frame; reference {:.0f} ms (all cores)",
      BounceSettings{}.clusters, def ? def->time_ms : 0.0, errors.at(fmt::format("box/{}", BounceSettings{}.clusters)),
      fig ? fig->time_ms : 0.0, reference_ms);
  report.publish(cluster_counts.size() + 1);
  fmt::print("{}\n", report.note);
  return 0;
}
