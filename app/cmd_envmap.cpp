// lumar envmap: stitch an HDR lat-long environment map from a recorded, tracked sweep.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/camera_response.h"
#include "lumar/calib/envmap_stitcher.h"
#include "lumar/calib/hole_filling.h"
#include "lumar/calib/orientation_refinement.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/core/envmap.h"
#include "lumar/core/error.h"

namespace lumar::app {

namespace {

struct EnvmapOptions {
  std::string recording, out, coverage, preview, camera, corrections;
  int width = 1024;
  bool no_refine = false;
  bool no_fill = false;
  std::optional<double> azimuth_offset_deg;
};

// A progress bar on stderr: redrawn in place on a terminal, a line per tenth otherwise.
class Progress {
 public:
  Progress(std::string what, int total) : what_(std::move(what)), total_(std::max(1, total)), tty_(isatty(2)) {}
  void update(int done) {
    const int tenth = done * 10 / total_;
    if (tty_) {
      const int filled = done * 30 / total_;
      std::fprintf(stderr, "\r%s [%s%s] %d/%d", what_.c_str(), std::string(filled, '#').c_str(),
                   std::string(30 - filled, ' ').c_str(), done, total_);
      if (done == total_) std::fprintf(stderr, "\n");
    } else if (tenth != last_tenth_) {
      std::fprintf(stderr, "%s: %d/%d\n", what_.c_str(), done, total_);
    }
    last_tenth_ = tenth;
  }

 private:
  std::string what_;
  int total_;
  bool tty_;
  int last_tenth_ = -1;
};

calib::CameraResponse response_of(const capture::Session& session, const std::filesystem::path& dir) {
  if (session.radiometry.response == "srgb" || session.radiometry.response.empty()) return calib::srgb_response(1.0);
  return calib::load_camera_response(dir / session.radiometry.response);
}

void run_envmap(const EnvmapOptions& o) {
  const std::filesystem::path dir = o.recording;
  if (o.width <= 0 || o.width % 2 != 0 || o.width > 16384)
    throw InputError("--width " + std::to_string(o.width) + ": expected an even number of pixels up to 16384");
  const capture::RecordingReplay replay(dir);
  const capture::RecordingReader& reader = replay.reader();
  const capture::Session& session = replay.session();
  const auto& frames = reader.frames();
  if (frames.empty()) throw InputError(dir.string() + ": the recording has no frames; record a sweep first");

  CameraIntrinsics camera = session.camera;
  std::string camera_name = (dir / capture::kSessionFile).string();
  if (!o.camera.empty()) {
    camera = calib::load_camera_file(o.camera).intrinsics;
    camera_name = o.camera;
  }
  const cv::Size size = reader.video().size;
  if (camera.width != size.width || camera.height != size.height)
    throw InputError(camera_name + ": the calibration is for " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " but the recording's frames are " + std::to_string(size.width) +
                     "x" + std::to_string(size.height) + "; use the calibration of the camera that recorded it");
  if (replay.tracker_stats().records == 0)
    throw InputError(dir.string() + ": the recording has no tracker poses; a sweep needs the tracker's stream");

  // Every frame needs a rotation from the tracker.
  std::vector<glm::dquat> tracked;
  glm::dvec3 mean_position(0.0);
  for (const auto& f : frames) {
    const auto pose = replay.tracked_camera_pose(f.time);
    if (!pose)
      throw InputError(dir.string() + ": the tracker poses do not cover frame " + std::to_string(f.index) + " at " +
                       std::to_string(nanos_to_seconds(f.time)) +
                       " s; the tracker must run from before the first frame to after the last");
    tracked.push_back(pose->rotation);
    mean_position += pose->translation / double(frames.size());
  }

  // Exposure per frame: a list cycled over the frames, or the session's one exposure.
  std::vector<double> exposures{session.radiometry.exposure};
  if (session.extra.contains("frame_exposures")) exposures = session.extra["frame_exposures"].get<std::vector<double>>();
  for (double e : exposures)
    if (!(e > 0) || !std::isfinite(e))
      throw InputError((dir / capture::kSessionFile).string() + ": exposures must be positive numbers");
  auto exposure_of = [&](std::int64_t index) { return exposures[std::size_t(index) % exposures.size()]; };

  calib::StitchSettings st;
  st.width = o.width;
  st.camera = camera;
  st.response = response_of(session, dir);
  st.vignetting_a = session.radiometry.vignetting_a;
  st.vignetting_b = session.radiometry.vignetting_b;
  st.capture_position = mean_position;
  if (session.extra.contains("envmap")) {
    const auto& e = session.extra["envmap"];
    if (e.contains("capture_position")) {
      const auto p = e["capture_position"].get<std::vector<double>>();
      if (p.size() == 3) st.capture_position = {p[0], p[1], p[2]};
    }
    st.azimuth_offset_deg = e.value("azimuth_offset_deg", 0.0);
  }
  if (o.azimuth_offset_deg) st.azimuth_offset_deg = *o.azimuth_offset_deg;

  const int n = int(frames.size());
  auto read_all = [&](const std::string& what, const std::function<void(const capture::Frame&, int)>& use) {
    auto source = replay.open_frames();
    Progress progress(what, n);
    capture::Frame frame;
    int k = 0;
    while (k < n && source->read(frame)) {
      use(frame, k);
      progress.update(++k);
    }
    if (k < n) throw InputError(dir.string() + ": the video ended after " + std::to_string(k) + " of " +
                                std::to_string(n) + " frames; the recording is damaged");
  };

  std::vector<glm::dquat> rotations = tracked;
  if (!o.no_refine) {
    std::vector<calib::FrameFeatures> features(n);
    read_all("features", [&](const capture::Frame& f, int k) {
      features[k] = calib::extract_frame_features(f.image, camera, st.response);
    });
    calib::RefinementSettings rs;
    if (session.extra.contains("synth")) rs.tracker_noise_deg = session.extra["synth"].value("tracker_noise_deg", 0.75);
    rs.tracker_noise_deg = std::max(rs.tracker_noise_deg, 0.05);
    // A bracket (session "exposure_bracket") was taken standing still: one rotation.
    std::vector<int> groups;
    if (session.extra.value("exposure_bracket", false))
      for (const auto& f : frames) groups.push_back(int(f.index / std::int64_t(exposures.size())));
    const auto result = calib::refine_orientations(features, tracked, rs, groups);
    rotations = result.rotations;
    double mean = 0, worst = 0;
    for (double c : result.correction_deg) mean += c / n, worst = std::max(worst, c);
    spdlog::info("envmap: refined {} frames from {} pairs ({} matches, {} frames unmatched): corrections mean {:.3f} "
                 "deg, max {:.3f} deg; match residual {:.3f} -> {:.3f} deg RMS",
                 n, result.pairs, result.matches, result.unmatched_frames, mean, worst, result.residual_before_deg,
                 result.residual_after_deg);
    if (!o.corrections.empty()) {
      const std::filesystem::path path = o.corrections, tmp = path.string() + ".tmp";
      {
        std::ofstream out(tmp);
        out << "index,time_ns,correction_deg,qw,qx,qy,qz\n";
        for (int k = 0; k < n; ++k)
          out << frames[k].index << ',' << frames[k].time << ',' << result.correction_deg[k] << ','
              << rotations[k].w << ',' << rotations[k].x << ',' << rotations[k].y << ',' << rotations[k].z << '\n';
        if (!out) throw InputError(o.corrections + ": cannot write the corrections; check the folder");
      }
      std::filesystem::rename(tmp, path);
    }
  }
  // With ground truth (synthetic recordings), say how close the rotations came.
  if (!reader.truth().empty()) {
    double before = 0, after = 0;
    int m = 0;
    for (int k = 0; k < n; ++k)
      if (auto truth = replay.true_camera_pose(frames[k].index)) {
        before += std::pow(rotation_angle_deg(tracked[k], truth->rotation), 2);
        after += std::pow(rotation_angle_deg(rotations[k], truth->rotation), 2);
        ++m;
      }
    if (m > 0)
      spdlog::info("envmap: rotation error against truth: tracker {:.3f} deg RMS, used {:.3f} deg RMS",
                   std::sqrt(before / m), std::sqrt(after / m));
  }

  calib::EnvmapStitcher stitcher(st);
  const auto t0 = std::chrono::steady_clock::now();
  read_all("stitching", [&](const capture::Frame& f, int k) { stitcher.add_frame(f.image, rotations[k], exposure_of(f.index)); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EnvironmentMap map = stitcher.current_map();
  const cv::Mat coverage = stitcher.coverage();
  const int covered = cv::countNonZero(coverage);
  int filled = 0;
  if (!o.no_fill && covered > 0) filled = calib::fill_holes_push_pull(map, coverage);
  save_environment_map(o.out, map);
  if (!o.coverage.empty()) calib::write_image_atomically(o.coverage, calib::coverage_image(coverage));
  if (!o.preview.empty()) calib::write_image_atomically(o.preview, calib::contact_sheet(map, coverage));
  spdlog::info("envmap: wrote {} ({}x{}, {:.1f} % covered, {} pixels filled; {} frames in {:.2f} s incl. decoding)",
               o.out, map.width, map.height, 100.0 * covered / coverage.total(), filled, n, seconds);
}

}  // namespace

void register_envmap(CLI::App& app) {
  auto o = std::make_shared<EnvmapOptions>();
  auto* cmd = app.add_subcommand("envmap", "Stitch an HDR environment map from a recorded, tracked camera sweep");
  cmd->add_option("--recording", o->recording, "Recording directory of the sweep")->required();
  cmd->add_option("--out", o->out, "Output map (OpenEXR, float RGB)")->required();
  cmd->add_option("--width", o->width, "Map width in pixels (height = width / 2)")->capture_default_str();
  cmd->add_flag("--no-refine", o->no_refine, "Use the tracker's rotations as they are");
  cmd->add_flag("--no-fill", o->no_fill, "Leave uncovered pixels black instead of filling them");
  cmd->add_option("--coverage", o->coverage, "Write a coverage map (PNG): magenta holes, grey by frame count");
  cmd->add_option("--preview", o->preview, "Write a tone-mapped contact sheet (PNG) at -4, 0, +4 stops");
  cmd->add_option("--corrections", o->corrections, "Write each frame's refined rotation and correction (CSV)");
  cmd->add_option("--camera", o->camera, "Camera calibration to use instead of the recording's");
  cmd->add_option("--azimuth-offset", o->azimuth_offset_deg, "Azimuth offset of the map about +Y, degrees");
  add_action(cmd, [o] { run_envmap(*o); });
}

}  // namespace lumar::app
