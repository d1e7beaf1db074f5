// Order-2 SH lighting: the quality knob is the resolution of the map the nine
// coefficients are projected from; the error is irradiance against a brute-force
// integral over the full-resolution map. Baseline: projecting the full map.
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <random>

#include "bench_report.h"
#include "lumar/base/latlong.h"
#include "lumar/lighting/sh.h"
#include "lumar/scene/envmap.h"

using namespace lumar;

namespace {

const EnvironmentMap& full_map() {
  static EnvironmentMap m = load_environment_map(std::filesystem::path(LUMAR_SOURCE_DIR) / "data/envmaps/interior.exr");
  return m;
}

EnvironmentMap downsampled(const EnvironmentMap& m, int factor) {
  if (factor == 1) return m;
  cv::Mat src(m.height, m.width, CV_32FC3, const_cast<float*>(m.rgb.data())), dst;
  cv::resize(src, dst, cv::Size(m.width / factor, m.height / factor), 0, 0, cv::INTER_AREA);
  EnvironmentMap out = m;
  out.width = dst.cols;
  out.height = dst.rows;
  out.rgb.assign(dst.ptr<float>(), dst.ptr<float>() + dst.total() * 3);
  return out;
}

std::vector<glm::dvec3> normals() {
  std::mt19937 rng(11);
  std::normal_distribution<double> n;
  std::vector<glm::dvec3> out;
  for (int i = 0; i < 64; ++i) out.push_back(glm::normalize(glm::dvec3(n(rng), n(rng), n(rng))));
  return out;
}

// E(n) by summing every texel of the full map: the reference.
glm::dvec3 brute_force_irradiance(const EnvironmentMap& m, const glm::dvec3& n) {
  glm::dvec3 e(0.0);
  for (int r = 0; r < m.height; ++r) {
    const double dw = latlong_pixel_solid_angle(r, m.width, m.height);
    for (int c = 0; c < m.width; ++c) {
      const double cosine = glm::dot(n, m.world_direction(latlong_pixel_direction(c, r, m.width, m.height)));
      if (cosine > 0) e += glm::dvec3(m.texel(c, r)) * (cosine * dw);
    }
  }
  return e;
}

double mean_relative_error_percent(const SH9& sh, const std::vector<glm::dvec3>& ns,
                                   const std::vector<glm::dvec3>& ref) {
  double sum = 0;
  for (std::size_t i = 0; i < ns.size(); ++i) {
    const glm::dvec3 e = sh9_irradiance(sh, ns[i]);
    const double lum_ref = glm::dot(ref[i], glm::dvec3(0.2126, 0.7152, 0.0722));
    sum += std::abs(glm::dot(e - ref[i], glm::dvec3(0.2126, 0.7152, 0.0722))) / lum_ref;
  }
  return 100.0 * sum / ns.size();
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<int> factors = {1, 2, 4, 8, 16, 32, 64};
  std::map<int, EnvironmentMap> maps;
  for (int f : factors) {
    maps[f] = downsampled(full_map(), f);
    benchmark::RegisterBenchmark(("sh9_projection/" + std::to_string(maps[f].width)).c_str(),
                                 [&maps, f](benchmark::State& state) {
                                   for (auto _ : state) benchmark::DoNotOptimize(project_radiance_sh9(maps[f]));
                                 })
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  bench::CollectingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  const auto ns = normals();
  std::vector<glm::dvec3> ref;
  for (const auto& n : ns) ref.push_back(brute_force_irradiance(full_map(), n));
  bench::BenchReport report;
  report.name = "sh9_projection";
  report.title = "Order-2 SH from interior.exr: projection time vs irradiance error (64 normals)";
  report.error_label = "mean relative irradiance error vs brute force (%)";
  for (int f : factors) {
    const std::string key = "sh9_projection/" + std::to_string(maps[f].width);
    const auto* result = reporter.find(key);
    if (!result) continue;
    const std::string name = fmt::format("{}x{}", maps[f].width, maps[f].height);
    if (f == 1) report.baseline = name;
    report.entries.push_back(
        {name, result->time_ms, mean_relative_error_percent(project_radiance_sh9(maps[f]), ns, ref)});
  }
  report.compute_ratios();
  report.save(bench::results_dir());
  return 0;
}
