// lumar calibrate-response and lumar calibrate-vignetting: the camera's radiometry,
// from a bracket of exposures and from flat-field images, optionally written into a
// recording's session.json so that later overlays use it.
#include <spdlog/spdlog.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/camera_response.h"
#include "lumar/calib/image_file.h"
#include "lumar/calib/vignetting.h"
#include "lumar/capture/session.h"

namespace lumar::app {

namespace {

cv::Mat read_image8(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": no such image");
  cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) throw InputError(path + ": cannot decode this image; give a PNG or JPEG file");
  return image;
}

struct ResponseOptions {
  std::vector<std::string> images;
  std::vector<double> times;
  std::string out, hdr, session;
  bool json = false;
};

void run_response(const ResponseOptions& o) {
  if (o.images.size() != o.times.size())
    throw InputError("calibrate-response: " + std::to_string(o.images.size()) + " images but " +
                     std::to_string(o.times.size()) + " exposure times; give one time per image");
  std::vector<cv::Mat> images;
  for (const auto& path : o.images) images.push_back(read_image8(path));
  const calib::CameraResponse response = calib::recover_response_debevec(images, o.times);
  calib::save_camera_response(o.out, response);
  if (!o.hdr.empty()) {
    const cv::Mat hdr = calib::merge_hdr(images, o.times, response);
    calib::write_image_atomically(o.hdr, hdr);
  }
  if (!o.session.empty())
    capture::update_session_file(
        o.session, [&](capture::Session& s) { s.radiometry.response = std::filesystem::absolute(o.out).string(); });

  // Linear exposure at a few codes, per channel (BGR), normalised so 128 -> 1.
  nlohmann::json summary = {{"out", o.out}, {"images", o.images.size()}};
  for (int c = 0; c < 3; ++c)
    summary["samples"][c == 0 ? "b" : (c == 1 ? "g" : "r")] = {response(c, 32), response(c, 64), response(c, 128),
                                                               response(c, 192), response(c, 250)};
  if (o.json) {
    std::printf("%s\n", summary.dump(2).c_str());
  } else {
    std::printf("camera response from %zu exposures -> %s\n", images.size(), o.out.c_str());
    std::printf("relative exposure at codes 32 64 128 192 250 (green): %s\n", summary["samples"]["g"].dump().c_str());
  }
}

struct VignettingOptions {
  std::vector<std::string> images;
  std::string camera, response, session;
  bool json = false;
};

void run_vignetting(const VignettingOptions& o) {
  if (o.images.empty()) throw InputError("calibrate-vignetting: give at least one flat-field image");
  const CameraIntrinsics camera = calib::load_camera_file(o.camera).intrinsics;
  const calib::CameraResponse response =
      o.response.empty() ? calib::srgb_response() : calib::load_camera_response(o.response);
  cv::Mat sum;
  for (const auto& path : o.images) {
    const cv::Mat image = read_image8(path);
    if (image.cols != camera.width || image.rows != camera.height)
      throw InputError(path + ": is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) + " but " +
                       o.camera + " describes a " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                       " camera");
    const cv::Mat linear = calib::linearize(image, response);
    if (sum.empty()) sum = cv::Mat::zeros(linear.size(), linear.type());
    sum += linear;
  }
  sum /= double(o.images.size());
  const calib::VignettingFit fit = calib::estimate_vignetting(sum, camera.cx, camera.cy);
  if (!o.session.empty())
    capture::update_session_file(o.session, [&](capture::Session& s) {
      s.radiometry.vignetting_a = fit.a;
      s.radiometry.vignetting_b = fit.b;
    });
  if (o.json) {
    const nlohmann::json j = {{"a", fit.a},
                              {"b", fit.b},
                              {"level", fit.level},
                              {"residual_rms", fit.residual_rms},
                              {"inliers", fit.inliers},
                              {"samples", fit.samples}};
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("vignetting gain 1 %+.4f r^2 %+.4f r^4 (residual %.2f %% RMS, %d of %d blocks)\n", fit.a, fit.b,
                100.0 * fit.residual_rms, fit.inliers, fit.samples);
  }
}

}  // namespace

void register_radiometry(CLI::App& app) {
  auto r = std::make_shared<ResponseOptions>();
  auto* response = app.add_subcommand("calibrate-response",
                                      "Recover the camera response (Debevec-Malik) from a bracket of exposures");
  response->add_option("--images", r->images, "The bracket: images of one static view")->required();
  response->add_option("--times", r->times, "Exposure time of each image, seconds, in the same order")
      ->required()
      ->check(CLI::PositiveNumber);
  response->add_option("--out", r->out, "Response JSON to write")->required();
  response->add_option("--hdr", r->hdr, "Also write the merged HDR image (.hdr)");
  response->add_option("--session", r->session, "Recording folder whose session.json should use this response");
  response->add_flag("--json", r->json, "Print a JSON summary");
  add_action(response, [r] {
    if (!r->hdr.empty() && std::filesystem::path(r->hdr).extension() != ".hdr")
      throw InputError(r->hdr + ": the merged image must be a .hdr (Radiance) file");
    run_response(*r);
  });

  auto v = std::make_shared<VignettingOptions>();
  auto* vignetting =
      app.add_subcommand("calibrate-vignetting", "Fit the radial fall-off 1 + a r^2 + b r^4 to flat-field images");
  vignetting->add_option("--images", v->images, "Flat-field images (averaged)")->required();
  vignetting->add_option("--camera", v->camera, "Camera file (its principal point and size)")->required();
  vignetting->add_option("--response", v->response, "Camera response JSON; default: sRGB");
  vignetting->add_option("--session", v->session, "Recording folder whose session.json should use this fit");
  vignetting->add_flag("--json", v->json, "Print a JSON summary");
  add_action(vignetting, [v] { run_vignetting(*v); });
}

}  // namespace lumar::app
