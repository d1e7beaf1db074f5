// lumar calibrate: camera intrinsics from views of a checkerboard or a ChArUco board.
#include <spdlog/spdlog.h>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include <fmt/format.h>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/glob.h"
#include "lumar/base/output_file.h"
#include "lumar/base/stop_signal.h"
#include "lumar/calib/calibration_report.h"
#include "lumar/calib/charuco_calibration.h"
#include "lumar/calib/checkerboard_calibration.h"
#include "lumar/calib/video_views.h"
#include "lumar/capture/source_spec.h"

namespace lumar::app {

namespace {

struct CalibrateOptions {
  std::vector<std::string> images;
  std::string board = "9x6";
  double square = 0.025;
  std::string out;
  bool json = false;
  std::string coverage, preview;
  calib::RobustCalibrationOptions calib;
  bool no_reject = false;
  std::string video;   // --video FILE: the same as --source video:FILE
  std::string source;  // --source SPEC --every N instead of --images
  int every = 10;
  int max_frames = 500;
  std::string charuco;  // --charuco SQUARESxSQUARES: a ChArUco board instead of a checkerboard
  double marker = 0.0;
  std::string dict = "DICT_5X5_100";
};

// The most squares a board may have along the image's longer and shorter sides: each
// square must cover at least kMinSquarePx pixels, or the detector cannot find its corners
// (and an absurd size such as 100000x100000 made it allocate for 45 s before bad_alloc).
constexpr int kMinSquarePx = 5;

void check_board_fits(const std::string& option, const std::string& text, cv::Size squares, cv::Size image) {
  const int most_long = std::max(image.width, image.height) / kMinSquarePx;
  const int most_short = std::min(image.width, image.height) / kMinSquarePx;
  if (std::max(squares.width, squares.height) > most_long || std::min(squares.width, squares.height) > most_short)
    throw InputError(fmt::format(
        "{} {}: a board of {}x{} squares cannot be seen in a {}x{} image (at most {}x{} "
        "squares of {} px); give the board's inner corners, e.g. 9x6",
        option, text, squares.width, squares.height, image.width, image.height, most_long, most_short, kMinSquarePx));
}

cv::Size parse_board(const std::string& option, const std::string& text, const char* what) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 2 || h < 2)
    throw InputError(option + " " + text + ": expected " + what);
  return {w, h};
}

// Expands globs (lumar/base/glob.h) and keeps plain paths as given.
std::vector<std::filesystem::path> expand(const std::vector<std::string>& patterns) {
  std::vector<std::filesystem::path> out;
  for (const auto& p : patterns) {
    if (!is_glob_pattern(p)) {
      out.emplace_back(p);
      continue;
    }
    const auto found = glob_files(p);
    if (found.empty()) throw InputError(p + ": no file matches this pattern");
    out.insert(out.end(), found.begin(), found.end());
  }
  return out;
}

// Every Nth frame of --source; a live camera delivers until --max-views frames are taken.
std::vector<calib::NamedImage> frames_from_source(const CalibrateOptions& o) {
  capture::SourceOptions options;
  options.fps = 30.0;  // an image sequence's timing does not matter here
  auto opened = capture::open_frame_source(o.source, options);
  if (opened.live)
    spdlog::info("calibrate: taking every {}th frame of {} until {} views; move the board around the image", o.every,
                 o.source, o.max_frames);
  return calib::sample_frames(*opened.source, o.every, o.max_frames);
}

}  // namespace

void register_calibrate(CLI::App& app) {
  auto o = std::make_shared<CalibrateOptions>();
  auto* cmd =
      app.add_subcommand("calibrate", "Calibrate camera intrinsics from views of a checkerboard or ChArUco board");
  cmd->add_option("--images", o->images, "Image files or glob patterns (quote globs)");
  cmd->add_option("--video", o->video, "A video file of the board instead of --images (as --source video:FILE)");
  cmd->add_option(
      "--source", o->source,
      "Frames instead of --images: video:FILE, images:GLOB, recording:DIR or a live camera v4l2:/dev/videoN");
  cmd->add_option("--every", o->every, "--video/--source: use every Nth frame")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--max-views", o->max_frames, "--video/--source: stop after this many sampled frames")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--charuco", o->charuco,
                  "A ChArUco board of SQUARESxSQUARES (squares, not corners) instead of --board");
  cmd->add_option("--marker", o->marker, "--charuco: marker side in metres")->check(CLI::PositiveNumber);
  cmd->add_option("--dict", o->dict, "--charuco: ArUco dictionary")->capture_default_str();
  cmd->add_option("--board", o->board, "Inner corners of the board, WxH")->capture_default_str();
  cmd->add_option("--square", o->square, "Square size in metres")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--out", o->out, "Calibration file to write (OpenCV YAML)")->required();
  cmd->add_flag("--json", o->json, "Print a machine-readable summary to stdout");
  cmd->add_flag("--fix-k3", o->calib.fix_k3, "Keep k3 at 0 (narrow-angle lenses)");
  cmd->add_flag("--fix-aspect", o->calib.fix_aspect, "Solve with fx = fy");
  cmd->add_flag("--no-reject", o->no_reject, "Keep every view (no outlier rejection)");
  cmd->add_option("--coverage", o->coverage,
                  "Write a PNG of where the corners fell on the sensor, with a legend and the areas still missing");
  cmd->add_option("--preview", o->preview,
                  "Write a PNG of the most distorted view as recorded and undistorted, to judge the result by eye");
  add_action(cmd, [o] {
    if (!o->video.empty()) {
      if (!o->source.empty()) throw InputError("calibrate: give --video or --source, not both");
      o->source = "video:" + o->video;
    }
    if (o->images.empty() == o->source.empty())
      throw InputError("calibrate: give either --images or --source (or --video)");
    const std::vector<std::filesystem::path> inputs =
        o->source.empty() ? expand(o->images) : std::vector<std::filesystem::path>();
    refuse_output_over_input(o->out, inputs);
    refuse_output_over_input(o->coverage, inputs, "--coverage");
    refuse_output_over_input(o->preview, inputs, "--preview");
    // Outputs are checked before the work, so that a missing folder is known now, not
    // after it: an OutputFile checks its path when it is made (and writes nothing).
    for (const std::string& out : {o->out, o->coverage, o->preview})
      if (!out.empty()) OutputFile{out};
    catch_stop_signals();  // Ctrl-C stops between images or within a solve; nothing is written
    const std::vector<calib::NamedImage> images =
        o->source.empty() ? calib::load_board_images(inputs) : frames_from_source(*o);
    // Both boards give views for the same robust solve; the report names inner corners.
    calib::BoardViews views;
    cv::Size board;
    if (!o->charuco.empty()) {
      const cv::Size squares = parse_board("--charuco", o->charuco, "squares as WxH, e.g. 7x5");
      if (!images.empty()) check_board_fits("--charuco", o->charuco, squares, images.front().image.size());
      if (!(o->marker > 0)) throw InputError("--charuco: give the marker side with --marker (metres)");
      views = calib::detect_charuco_views(images, {squares.width, squares.height, o->square, o->marker, o->dict});
      board = {squares.width - 1, squares.height - 1};
    } else {
      board = parse_board("--board", o->board, "inner corners as WxH, e.g. 9x6");
      if (!images.empty()) check_board_fits("--board", o->board, board + cv::Size(1, 1), images.front().image.size());
      views = calib::detect_checkerboard_views(images, board, o->square);
    }
    auto options = o->calib;
    options.reject_outliers = !o->no_reject;
    // OpenCV's solve is dense, a minute or more over a hundred views: say why it waits (on
    // stderr, as progress is: stdout may be --json).
    if (views.corners.size() >= 50)
      std::fprintf(stderr, "calibrate: solving from %zu views, which takes a while with this many%s\n",
                   views.corners.size(), options.reject_outliers ? " (again for each outlier rejected)" : "");
    const auto result = calib::calibrate_robust(views, options);
    if (!o->coverage.empty()) calib::write_coverage_image(o->coverage, views, result, options);
    if (!o->preview.empty()) calib::write_undistorted_preview(o->preview, images, views, result);
    calib::save_calibration_report(o->out, result, board, o->square);
    for (const auto& w : result.warnings) std::fprintf(stderr, "lumar: warning: %s\n", w.c_str());
    const auto& c = result.camera.intrinsics;
    if (o->json) {
      nlohmann::json std_dev = nlohmann::json::object();
      for (std::size_t i = 0; i < calib::kIntrinsicNames.size(); ++i)
        std_dev[calib::kIntrinsicNames[i]] = result.std_dev[i];
      nlohmann::json rejected = nlohmann::json::array(), rejections = nlohmann::json::array();
      for (const auto& v : result.rejected) {
        rejected.push_back(v.name);
        rejections.push_back({{"file", v.name}, {"rms", v.rms_px}, {"threshold", v.threshold_px}, {"round", v.round}});
      }
      nlohmann::json j = {{"rms", result.camera.avg_reprojection_error},
                          {"initial_rms", result.initial_rms},
                          {"fx", c.fx},
                          {"fy", c.fy},
                          {"cx", c.cx},
                          {"cy", c.cy},
                          {"dist", c.distortion},
                          {"std", std_dev},
                          {"views_used", result.used_views.size()},
                          {"used_views", result.used_views},
                          {"views_rejected", rejected},
                          {"rejections", rejections},
                          {"views_without_board", result.views_without_board},
                          {"per_view_rms", result.per_view_rms},
                          {"holdout_rms", result.holdout_rms},
                          {"holdout_training_rms", result.training_rms},
                          {"holdout_splits", result.holdout_splits},
                          {"coverage", result.coverage},
                          {"orientations", result.orientations},
                          {"warnings", result.warnings}};
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      spdlog::info("calibrate: {} views kept, {} rejected; RMS {:.3f} px (all views {:.3f} px) -> {}",
                   result.used_views.size(), result.rejected.size(), result.camera.avg_reprojection_error,
                   result.initial_rms, o->out);
      spdlog::info("  fx {:.2f} ± {:.2f}  fy {:.2f} ± {:.2f}  cx {:.2f} ± {:.2f}  cy {:.2f} ± {:.2f}", c.fx,
                   result.std_dev[0], c.fy, result.std_dev[1], c.cx, result.std_dev[2], c.cy, result.std_dev[3]);
      spdlog::info(
          "  k1 {:.4f} ± {:.4f}  k2 {:.4f} ± {:.4f}  p1 {:.5f} ± {:.5f}  p2 {:.5f} ± {:.5f}  k3 {:.4f} ± {:.4f}",
          c.distortion[0], result.std_dev[4], c.distortion[1], result.std_dev[5], c.distortion[2], result.std_dev[6],
          c.distortion[3], result.std_dev[7], c.distortion[4], result.std_dev[8]);
      spdlog::info(
          "  held-out RMS {:.3f} px over {} half/half splits (training halves {:.3f} px); coverage {:.0f}%, "
          "{} board orientations",
          result.holdout_rms, result.holdout_splits, result.training_rms, 100 * result.coverage, result.orientations);
      for (const auto& v : result.rejected)
        spdlog::info("  rejected {}: {:.3f} px > threshold {:.3f} px (round {})", v.name, v.rms_px, v.threshold_px,
                     v.round);
      for (std::size_t i = 0; i < result.used_views.size(); ++i)
        spdlog::info("  {}: {:.3f} px", result.used_views[i], result.per_view_rms[i]);
    }
  });
}

}  // namespace lumar::app
