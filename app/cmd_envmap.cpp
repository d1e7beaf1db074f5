// lumar envmap: stitch an HDR lat-long environment map from a tracked sweep: a
// recording, a folder of images with poses, or a live camera with a tracker.
#include <spdlog/spdlog.h>

#include <memory>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/calib/camera_file.h"
#include "lumar/calib/camera_response.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/envmap_images.h"
#include "lumar/pipeline/envmap_live.h"
#include "lumar/pipeline/envmap_sweep.h"

namespace lumar::app {

namespace {

struct EnvmapOptions {
  EnvmapOutputOptions out;
  std::string recording, export_images;
  ImagesInputOptions images;
  LiveEnvmapOptions live;
};

calib::CameraResponse response_of(const capture::Session& session, const std::filesystem::path& dir) {
  if (session.radiometry.response == "srgb" || session.radiometry.response.empty()) return calib::srgb_response(1.0);
  return calib::load_camera_response(dir / session.radiometry.response);
}

// The recording's frames, the tracker's rotation at each frame's time, the exposures
// (session "frame_exposures", cycled, or its one exposure), brackets as groups.
SweepInput recording_sweep_input(const std::string& recording, const std::string& camera_file, int width) {
  const std::filesystem::path dir = recording;
  auto replay = std::make_shared<const capture::RecordingReplay>(dir);
  const capture::RecordingReader& reader = replay->reader();
  const capture::Session& session = replay->session();
  const auto& frames = reader.frames();
  if (frames.empty()) throw InputError(dir.string() + ": the recording has no frames; record a sweep first");

  SweepInput in;
  in.name = dir.string();
  CameraIntrinsics camera = session.camera;
  std::string camera_name = (dir / capture::kSessionFile).string();
  if (!camera_file.empty()) {
    camera = calib::load_camera_file(camera_file).intrinsics;
    camera_name = camera_file;
  }
  const cv::Size size = reader.video().size;
  if (camera.width != size.width || camera.height != size.height)
    throw InputError(camera_name + ": the calibration is for " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " but the recording's frames are " + std::to_string(size.width) +
                     "x" + std::to_string(size.height) + "; use the calibration of the camera that recorded it");
  if (replay->tracker_stats().records == 0)
    throw InputError(dir.string() + ": the recording has no tracker poses; a sweep needs the tracker's stream");

  glm::dvec3 mean_position(0.0);
  for (const auto& f : frames) {
    const auto pose = replay->tracked_camera_pose(f.time);
    if (!pose)
      throw InputError(dir.string() + ": the tracker poses do not cover frame " + std::to_string(f.index) + " at " +
                       std::to_string(nanos_to_seconds(f.time)) +
                       " s; the tracker must run from before the first frame to after the last");
    in.rotations.push_back(pose->rotation);
    in.labels.push_back(std::to_string(f.index) + "," + std::to_string(f.time));
    mean_position += pose->translation / double(frames.size());
  }
  in.label_header = "index,time_ns";

  const std::size_t cycle = std::max<std::size_t>(1, session.frame_exposures.size());
  for (const auto& f : frames) {
    in.exposures.push_back(session.frame_exposure(f.index));
    if (session.exposure_bracket) in.groups.push_back(int(f.index / std::int64_t(cycle)));
  }

  calib::StitchSettings& st = in.stitch;
  st.width = width;
  st.camera = camera;
  st.response = response_of(session, dir);
  st.vignetting_a = session.radiometry.vignetting_a;
  st.vignetting_b = session.radiometry.vignetting_b;
  st.capture_position = mean_position;
  if (session.envmap) {
    if (session.envmap->capture_position) st.capture_position = *session.envmap->capture_position;
    st.azimuth_offset_deg = session.envmap->azimuth_offset_deg;
    // The map a synthetic sweep was made from: the output is compared with it.
    const std::string& source_map = session.envmap->source_map;
    if (std::error_code ec; !source_map.empty() && std::filesystem::exists(source_map, ec))
      in.default_reference = source_map;
  }
  if (session.synth) in.tracker_noise_deg = session.synth->tracker_noise_deg;

  if (!reader.truth().empty())
    for (const auto& f : frames) {
      const auto truth = replay->true_camera_pose(f.index);
      in.truth.push_back(truth ? std::optional<glm::dquat>(truth->rotation) : std::nullopt);
    }
  const int n = int(frames.size());
  in.read_frames = [replay, n](const std::function<void(const cv::Mat&, int)>& use) {
    auto source = replay->open_frames();
    capture::Frame frame;
    for (int k = 0; k < n && source->read(frame); ++k) use(frame.image, k);
  };
  return in;
}

void run_envmap(EnvmapOptions& o) {
  const int inputs = int(!o.recording.empty()) + int(!o.images.images.empty()) + int(!o.live.in.source.empty());
  if (inputs != 1) throw InputError("envmap: give exactly one of --recording DIR, --images DIR_OR_GLOB, --source SPEC");
  check_map_width(o.out.width);
  if (o.out.out.empty() && o.export_images.empty()) throw InputError("envmap: --out OUT.exr is required");
  if (std::error_code ec; !o.out.reference.empty() && !std::filesystem::is_regular_file(o.out.reference, ec))
    throw InputError(o.out.reference + ": no such reference map; check --reference");
  if (!o.export_images.empty() && o.recording.empty())
    throw InputError("--export-images writes a recording's frames; it needs --recording");
  if (!o.live.in.source.empty()) {
    if (!o.out.corrections.empty() && !o.live.refine_at_end)
      throw InputError("--corrections: a live sweep is refined only with --refine-at-end");
    o.live.out = o.out;
    o.live.response = o.images.response;
    o.live.vignetting_a = o.images.vignetting_a;
    o.live.vignetting_b = o.images.vignetting_b;
    o.live.tracker_noise_deg = o.images.tracker_noise_deg;
    run_live_envmap(o.live);
    return;
  }
  SweepInput in;
  if (!o.recording.empty()) {
    in = recording_sweep_input(o.recording, o.live.in.camera_file, o.out.width);
  } else {
    o.images.camera = o.live.in.camera_file;
    in = images_sweep_input(o.images, o.out.width);
  }
  if (o.out.azimuth_offset_deg) in.stitch.azimuth_offset_deg = *o.out.azimuth_offset_deg;
  if (!o.export_images.empty()) {
    export_sweep_images(in, o.export_images);
    spdlog::info("envmap: wrote {} frames and their poses to {}", in.rotations.size(), o.export_images);
    if (o.out.out.empty()) return;
  }
  stitch_sweep(in, o.out);
}

}  // namespace

void register_envmap(CLI::App& app) {
  auto o = std::make_shared<EnvmapOptions>();
  auto* cmd = app.add_subcommand("envmap",
                                 "Stitch an HDR environment map from a tracked camera sweep: a recording, images with "
                                 "poses, or a live camera with a tracker");
  cmd->add_option("--recording", o->recording, "Recording directory of the sweep");
  cmd->add_option("--images", o->images.images, "Folder or glob of the sweep's images (with --poses and --camera)");
  cmd->add_option("--poses", o->images.poses, "--images: CSV file,qw,qx,qy,qz[,x,y,z][,exposure][,station]");
  cmd->add_option("--response", o->images.response, "--images, --source: camera response JSON (default: sRGB)");
  cmd->add_option("--vignetting", o->images.vignetting_a,
                  "--images, --source: vignetting gain 1 + a r^2 + b r^4, the a term");
  cmd->add_option("--vignetting-b", o->images.vignetting_b, "--images, --source: vignetting, the b term");
  cmd->add_option("--tracker-noise-deg", o->images.tracker_noise_deg,
                  "--images, --source: RMS error of the poses' rotations (the refinement's prior)")
      ->capture_default_str();
  cmd->add_option("--out", o->out.out, "Output map (OpenEXR, float RGB)");
  cmd->add_option("--width", o->out.width, "Map width in pixels (height = width / 2)")->capture_default_str();
  cmd->add_flag("--no-refine", o->out.no_refine, "Use the tracker's rotations as they are");
  cmd->add_flag("--no-fill", o->out.no_fill, "Leave uncovered pixels black instead of filling them");
  cmd->add_option("--coverage", o->out.coverage, "Write a coverage map (PNG): magenta holes, grey by frame count");
  cmd->add_option("--preview", o->out.preview, "Write a tone-mapped contact sheet (PNG) at -4, 0, +4 stops");
  cmd->add_option("--corrections", o->out.corrections, "Write each frame's refined rotation and correction (CSV)");
  cmd->add_option("--reference", o->out.reference,
                  "Compare the result with this map (default: a synthetic recording's source map)");
  cmd->add_option("--azimuth-offset", o->out.azimuth_offset_deg, "Azimuth offset of the map about +Y, degrees");
  cmd->add_option("--export-images", o->export_images,
                  "--recording: also write its frames and tracked poses as an --images folder (new)");
  add_live_envmap_options(cmd, o->live);
  add_action(cmd, [o] { run_envmap(*o); });
}

}  // namespace lumar::app
