// lumar calibrate: camera intrinsics from checkerboard images.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "lumar/calib/checkerboard_calibration.h"
#include "lumar/core/error.h"

namespace lumar::app {

namespace {

struct CalibrateOptions {
  std::vector<std::string> images;
  std::string board = "9x6";
  double square = 0.025;
  std::string out;
  bool json = false;
};

cv::Size parse_board(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 2 || h < 2)
    throw InputError("--board " + text + ": expected inner corners as WxH, e.g. 9x6");
  return {w, h};
}

// Expands globs (OpenCV's cv::glob) and keeps plain paths as given.
std::vector<std::filesystem::path> expand(const std::vector<std::string>& patterns) {
  std::vector<std::filesystem::path> out;
  for (const auto& p : patterns) {
    if (p.find_first_of("*?[") == std::string::npos) {
      out.emplace_back(p);
      continue;
    }
    std::vector<cv::String> found;
    cv::glob(p, found, false);
    if (found.empty()) throw InputError(p + ": no file matches this pattern");
    std::sort(found.begin(), found.end());
    out.insert(out.end(), found.begin(), found.end());
  }
  return out;
}

}  // namespace

void register_calibrate(CLI::App& app) {
  auto o = std::make_shared<CalibrateOptions>();
  auto* cmd = app.add_subcommand("calibrate", "Calibrate camera intrinsics from checkerboard images");
  cmd->add_option("--images", o->images, "Image files or glob patterns (quote globs)")->required();
  cmd->add_option("--board", o->board, "Inner corners of the board, WxH")->capture_default_str();
  cmd->add_option("--square", o->square, "Square size in metres")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--out", o->out, "Calibration file to write (OpenCV YAML)")->required();
  cmd->add_flag("--json", o->json, "Print a machine-readable summary to stdout");
  add_action(cmd, [o] {
    const auto result = calib::calibrate_checkerboard(expand(o->images), parse_board(o->board), o->square);
    calib::save_camera_file(o->out, result.camera);
    const auto& c = result.camera.intrinsics;
    if (o->json) {
      nlohmann::json j = {{"rms", result.camera.avg_reprojection_error},
                          {"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx}, {"cy", c.cy},
                          {"dist", c.distortion}, {"views_used", result.used_views.size()},
                          {"views_without_board", result.views_without_board},
                          {"per_view_rms", result.per_view_rms}};
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      spdlog::info("calibrate: {} views, RMS {:.3f} px, fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f} -> {}",
                   result.used_views.size(), result.camera.avg_reprojection_error, c.fx, c.fy, c.cx, c.cy, o->out);
      for (std::size_t i = 0; i < result.used_views.size(); ++i)
        spdlog::info("  {}: {:.3f} px", result.used_views[i], result.per_view_rms[i]);
    }
  });
}

}  // namespace lumar::app
