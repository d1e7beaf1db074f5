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
#include "lumar/pipeline/envmap_recording.h"
#include "lumar/pipeline/envmap_sweep.h"

namespace lumar::app {

namespace {

struct EnvmapOptions {
  pipeline::EnvmapOutputOptions out;
  std::string recording, export_images;
  pipeline::ImagesInputOptions images;
  pipeline::LiveEnvmapOptions live;
};

void run_envmap(EnvmapOptions& o) {
  const int inputs = int(!o.recording.empty()) + int(!o.images.images.empty()) + int(!o.live.in.source.empty());
  if (inputs != 1) throw InputError("envmap: give exactly one of --recording DIR, --images DIR_OR_GLOB, --source SPEC");
  pipeline::check_map_width(o.out.width);
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
    pipeline::run_live_envmap(o.live);
    return;
  }
  pipeline::SweepInput in;
  if (!o.recording.empty()) {
    in = pipeline::recording_sweep_input(o.recording, o.live.in.camera_file, o.out.width);
  } else {
    o.images.camera = o.live.in.camera_file;
    in = pipeline::images_sweep_input(o.images, o.out.width);
  }
  if (o.out.azimuth_offset_deg) in.stitch.azimuth_offset_deg = *o.out.azimuth_offset_deg;
  if (!o.export_images.empty()) {
    pipeline::export_sweep_images(in, o.export_images);
    spdlog::info("envmap: wrote {} frames and their poses to {}", in.rotations.size(), o.export_images);
    if (o.out.out.empty()) return;
  }
  pipeline::stitch_sweep(in, o.out);
}

// The live options that do not clash with the file inputs' (--width is the map's, so
// the camera's frame size is --video-width / --video-height).
void add_live_envmap_options(CLI::App* cmd, pipeline::LiveEnvmapOptions& o) {
  pipeline::LiveInputOptions& in = o.in;
  cmd->add_option("--source", in.source,
                  "Live sweep: video:FILE | images:DIR_OR_GLOB | v4l2:/dev/videoN | recording:DIR (files play in "
                  "real time)");
  cmd->add_option("--rig", o.rig, "--source: a session.json whose rig (tracker to camera) to use (default: identity)");
  add_live_input_options(cmd, in,
                         "Camera calibration (OpenCV YAML): --images needs it; --recording: instead of the session's; "
                         "--source: default a nominal pinhole");
  cmd->add_option("--frame-exposure", o.exposures,
                  "--source: video linear value per unit radiance; a list E1,E2,... is cycled over the frames (a "
                  "recording: its own)")
      ->delimiter(',');
  cmd->add_option("--update-every", o.update_every_s, "--source: rewrite the outputs every this many seconds")
      ->capture_default_str();
  cmd->add_option("--duration", o.duration_s, "--source: stop after this many seconds (0: end of source or Ctrl-C)");
  cmd->add_flag("--refine-at-end", o.refine_at_end,
                "--source: keep the frames and, when the sweep ends, refine their rotations and stitch them again");
  cmd->add_option("--keep-frames", o.keep_frames, "--source --refine-at-end: most frames kept in memory")
      ->capture_default_str();
  cmd->add_option("--tracker-timeout", o.tracker_timeout_s,
                  "--source: seconds to wait for the tracker's first pose before giving up")
      ->capture_default_str();
  cmd->add_option("--max-wait-ms", o.max_wait_ms, "--source: longest a frame waits for the tracker's pose")
      ->capture_default_str();
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
  cmd->add_option("--min-coverage", o->out.min_coverage,
                  "Refuse a map whose frames saw less than this share of the sphere (0 to 1; hole filling invents "
                  "the rest)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
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
