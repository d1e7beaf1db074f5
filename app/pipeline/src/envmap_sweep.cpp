#include "lumar/pipeline/envmap_sweep.h"

#include <unistd.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "lumar/base/error.h"
#include "lumar/base/latlong.h"
#include "lumar/base/output_file.h"
#include "lumar/base/pose.h"
#include "lumar/base/stop_signal.h"
#include "lumar/calib/image_file.h"
#include "lumar/envmap/clipped_sources.h"
#include "lumar/envmap/envmap_quality.h"
#include "lumar/envmap/hole_filling.h"
#include "lumar/envmap/orientation_refinement.h"
#include "lumar/pipeline/progress.h"

namespace lumar::pipeline {

void check_map_width(int width) {
  if (width <= 0 || width % 2 != 0 || width > 16384)
    throw InputError("--width " + std::to_string(width) + ": expected an even number of pixels up to 16384");
}

std::optional<double> compare_with_reference(const EnvironmentMap& map, const cv::Mat& coverage,
                                             const std::string& reference) {
  if (reference.empty()) return std::nullopt;
  const EnvironmentMap source = load_environment_map(reference);
  if (source.width % map.width != 0) {
    spdlog::warn("envmap: not compared with {}: its width {} is not a multiple of {}", reference, source.width,
                 map.width);
    return std::nullopt;
  }
  const double error = calib::median_relative_luminance_error(map, calib::downsample_map(source, map.width), coverage);
  spdlog::info("envmap: against {}: median relative luminance error {:.2f} % on covered pixels", reference,
               100.0 * error);
  return error;
}

double write_envmap_outputs(EnvironmentMap map, const cv::Mat& coverage, const EnvmapOutputOptions& o, int* filled) {
  const int covered = cv::countNonZero(coverage);
  int n_filled = 0;
  if (!o.no_fill && covered > 0) n_filled = calib::fill_holes_push_pull(map, coverage);
  save_environment_map(o.out, map);
  if (!o.coverage.empty()) calib::write_image_atomically(o.coverage, calib::coverage_image(coverage));
  if (!o.preview.empty()) calib::write_image_atomically(o.preview, calib::contact_sheet(map, coverage));
  if (filled) *filled = n_filled;
  return double(covered) / double(coverage.total());
}

namespace {

void write_corrections(const SweepInput& in, const calib::RefinementResult& result, const std::string& path) {
  std::ostringstream out;
  out << in.label_header << ",correction_deg,qw,qx,qy,qz\n";
  out.precision(12);
  for (std::size_t k = 0; k < result.rotations.size(); ++k) {
    const glm::dquat& q = result.rotations[k];
    out << in.labels[k] << ',' << result.correction_deg[k] << ',' << q.w << ',' << q.x << ',' << q.y << ',' << q.z
        << '\n';
  }
  write_file_atomically(path, out.str());
}

}  // namespace

void warn_about_exposure_range(const calib::EnvmapStitcher& stitcher, const EnvironmentMap& map,
                               const std::vector<double>& exposures) {
  // Too dark: regions no exposure lifted clear of the sensor's noise.
  const cv::Mat dark = stitcher.near_black(), coverage = stitcher.coverage();
  double dark_sr = 0, covered_sr = 0;
  for (int r = 0; r < dark.rows; ++r) {
    const double omega = latlong_pixel_solid_angle(r, dark.cols, dark.rows);
    for (int c = 0; c < dark.cols; ++c) {
      if (coverage.at<std::uint16_t>(r, c) > 0) covered_sr += omega;
      if (dark.at<uchar>(r, c)) dark_sr += omega;
    }
  }
  if (covered_sr > 0 && dark_sr > kNearBlackShareWarned * covered_sr)
    spdlog::warn(
        "envmap: {:.1f} % of what the frames saw was below code {:.0f} in every frame, the longest exposure too, "
        "where the sensor's noise, clipped at black, makes it up to 40 % too bright; add an exposure 4 stops longer "
        "than "
        "the longest",
        100 * dark_sr / covered_sr, calib::EnvmapStitcher::kNearBlackCode);
  const cv::Mat clipped = stitcher.clipped();
  const auto sources = calib::find_clipped_sources(map, clipped);
  if (sources.empty() || exposures.empty()) return;
  const auto [shortest, longest] = std::minmax_element(exposures.begin(), exposures.end());
  const double under = std::log2(*longest / *shortest);
  // Only a lower bound is known, so the exposure that holds them is found by trying:
  // two stops further down at a time.
  spdlog::warn(
      "envmap: {} source(s) clipped in every frame, the shortest exposure ({:.1f} stops under the longest) too; the "
      "map holds only a lower bound there ({:.2f} % of its power as recorded), so their light and hard shadows are "
      "too weak. Add shorter exposures until they hold: next {:.1f} stops under the longest",
      sources.size(), under, 100 * calib::clipped_power_share(map, clipped), under + 2.0);
  for (std::size_t i = 0; i < sources.size() && i < 3; ++i) {
    const auto& s = sources[i];
    spdlog::warn(
        "envmap:   clipped source at azimuth {:.1f} deg, elevation {:.1f} deg: {} pixels, {:.2g} sr, "
        "luminance at least {:.4g}",
        s.azimuth_deg, s.elevation_deg, s.pixels, s.solid_angle, s.recorded_peak);
  }
}

void stitch_sweep(const SweepInput& in, const EnvmapOutputOptions& o) {
  const int n = int(in.rotations.size());
  if (n == 0) throw InputError(in.name + ": no frames; a sweep needs at least one");
  // Ctrl-C stops between frames, before any output is written.
  catch_stop_signals();
  auto read_all = [&](const std::string& what, const std::function<void(const cv::Mat&, int)>& use) {
    Progress progress(what, n);
    int done = 0;
    in.read_frames([&](const cv::Mat& image, int k) {
      if (stop_requested()) throw Interrupted(fmt::format("envmap: {} {} of {} frames; no map written", what, done, n));
      use(image, k);
      progress.update(++done);
    });
    if (done < n)
      throw InputError(in.name + ": only " + std::to_string(done) + " of " + std::to_string(n) +
                       " frames could be read; the input is damaged");
  };

  std::vector<glm::dquat> rotations = in.rotations;
  if (!o.no_refine) {
    std::vector<calib::FrameFeatures> features(n);
    read_all("features", [&](const cv::Mat& image, int k) {
      features[k] = calib::extract_frame_features(image, in.stitch.camera, in.stitch.response);
    });
    calib::RefinementSettings rs;
    rs.tracker_noise_deg = std::max(in.tracker_noise_deg, 0.05);
    const auto result = calib::refine_orientations(features, in.rotations, rs, in.groups);
    rotations = result.rotations;
    double mean = 0, worst = 0;
    for (double c : result.correction_deg) mean += c / n, worst = std::max(worst, c);
    spdlog::info(
        "envmap: refined {} frames from {} pairs ({} matches, {} frames unmatched): corrections mean {:.3f} "
        "deg, max {:.3f} deg; match residual {:.3f} -> {:.3f} deg RMS",
        n, result.pairs, result.matches, result.unmatched_frames, mean, worst, result.residual_before_deg,
        result.residual_after_deg);
    if (!o.corrections.empty()) write_corrections(in, result, o.corrections);
  }
  // With ground truth (synthetic sweeps), say how close the rotations came.
  double before = 0, after = 0;
  int m = 0;
  for (int k = 0; k < n && k < int(in.truth.size()); ++k)
    if (in.truth[k]) {
      before += std::pow(rotation_angle_deg(in.rotations[k], *in.truth[k]), 2);
      after += std::pow(rotation_angle_deg(rotations[k], *in.truth[k]), 2);
      ++m;
    }
  if (m > 0)
    spdlog::info("envmap: rotation error against truth: tracker {:.3f} deg RMS, used {:.3f} deg RMS",
                 std::sqrt(before / m), std::sqrt(after / m));

  calib::EnvmapStitcher stitcher(in.stitch);
  const auto t0 = std::chrono::steady_clock::now();
  read_all("stitching", [&](const cv::Mat& image, int k) { stitcher.add_frame(image, rotations[k], in.exposures[k]); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double sphere = calib::sphere_coverage(stitcher.coverage());
  if (sphere < o.min_coverage)
    throw InputError(in.name + ": the frames saw only " + fmt::format("{:.1f}", 100 * sphere) +
                     " % of the sphere, less than the " + fmt::format("{:.0f}", 100 * o.min_coverage) +
                     " % --min-coverage asks; hole filling would invent the rest: sweep the camera all around");
  if (sphere < kWellCoveredSphere)
    spdlog::warn("envmap: the frames saw {:.1f} % of the sphere; the other {:.1f} % is filled in, not measured",
                 100 * sphere, 100 * (1 - sphere));
  const EnvironmentMap map = stitcher.current_map();
  warn_about_exposure_range(stitcher, map, in.exposures);
  int filled = 0;
  const double covered = write_envmap_outputs(map, stitcher.coverage(), o, &filled);
  spdlog::info("envmap: wrote {} ({}x{}, {:.1f} % covered, {} pixels filled; {} frames in {:.2f} s incl. decoding)",
               o.out, stitcher.width(), stitcher.height(), 100.0 * covered, filled, n, seconds);
  compare_with_reference(map, stitcher.coverage(), o.reference.empty() ? in.default_reference : o.reference);
}

}  // namespace lumar::pipeline
