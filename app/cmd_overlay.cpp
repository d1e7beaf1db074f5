// lumar overlay: composite the scene's virtual objects into a recording's video.
#include <spdlog/spdlog.h>
#include <memory>
#include <optional>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/pipeline/live_overlay.h"
#include "lumar/pipeline/output_files.h"
#include "lumar/pipeline/replay_overlay.h"

namespace lumar::app {

namespace {
struct OverlayOptions {
  std::string recording, scene, out, frames_dir, contact_sheet, poses = "tracker", undistort = "same";
  bool window = false;
  int max_frames = 0;
  int adapt_lighting = 0;
};
}  // namespace

void register_overlay(CLI::App& app) {
  auto o = std::make_shared<OverlayOptions>();
  auto* cmd =
      app.add_subcommand("overlay", "Composite virtual objects into a recording's video (headless or in a window)");
  cmd->add_option("--recording", o->recording, "Recording directory (video + tracker stream + session.json)");
  // The live path (live_overlay.h): --source and --tracker instead of --recording.
  auto live = std::make_shared<pipeline::LiveOverlayOptions>();
  cmd->add_option("--source", live->in.source, "Live: video:FILE, images:DIR, v4l2:/dev/videoN or recording:DIR");
  cmd->add_option("--rig", live->rig, "Live: a session.json whose rig (transmitter, camera offset) to use");
  add_live_input_options(cmd, live->in);
  cmd->add_option("--scene", o->scene, "Scene manifest; default: the one the recording's session names");
  cmd->add_option("--out", o->out, "Output video (.mp4, .mkv or .avi)");
  cmd->add_option("--frames-dir", o->frames_dir, "Also write every output frame as PNG into this new folder");
  cmd->add_option("--contact-sheet", o->contact_sheet, "Also write 8 frames spread over the run, tiled, as one PNG");
  cmd->add_option("--poses", o->poses, "Camera poses from the tracker stream or from the recording's ground truth")
      ->check(CLI::IsMember({"tracker", "truth"}))
      ->capture_default_str();
  cmd->add_option(
         "--undistort", o->undistort,
         "Output camera: 'same' keeps the calibrated matrix, 'crop' shows only valid pixels, 'keep' every input pixel")
      ->check(CLI::IsMember({"same", "crop", "keep"}))
      ->capture_default_str();
  cmd->add_option(
         "--adapt-lighting", o->adapt_lighting,
         "Every N frames, compare the video with the map and follow the room getting brighter or darker (0 = off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--window", o->window, "Show the result in a window (needs a display)");
  cmd->add_option("--max-frames", o->max_frames, "Stop after this many frames (0 = all)")->capture_default_str();
  add_action(cmd, [o, live] {
    if (!live->in.source.empty()) {
      if (!o->recording.empty()) throw InputError("overlay: give --recording or --source, not both");
      live->scene = o->scene;
      live->max_frames = o->max_frames;
      return pipeline::run_live_overlay(*live);
    }
    if (o->recording.empty()) throw InputError("overlay: give --recording DIR, or --source SPEC for the live path");
    if (o->out.empty() && o->frames_dir.empty() && o->contact_sheet.empty() && !o->window)
      throw InputError("overlay: nothing to do; give --out, --frames-dir, --contact-sheet or --window");
    if (!o->contact_sheet.empty() && std::filesystem::path(o->contact_sheet).extension() != ".png")
      throw InputError(o->contact_sheet + ": the contact sheet must be a .png file");
    const auto undistortion = o->undistort == "crop"   ? calib::UndistortedCamera::CropToValid
                              : o->undistort == "keep" ? calib::UndistortedCamera::KeepAll
                                                       : calib::UndistortedCamera::SameMatrix;
    pipeline::ReplayOverlay overlay(o->recording, o->scene,
                                    o->poses == "truth" ? pipeline::PoseSource::Truth : pipeline::PoseSource::Tracker,
                                    o->window, undistortion, o->adapt_lighting);
    const auto& camera = overlay.compositor().output_camera();
    const double fps = overlay.replay().reader().video().fps;
    std::optional<pipeline::VideoOutput> video;
    std::optional<pipeline::FramesOutput> frames;
    if (!o->out.empty()) video.emplace(o->out, fps, cv::Size(camera.width, camera.height));
    if (!o->frames_dir.empty()) frames.emplace(o->frames_dir);
    // Eight frames spread evenly over the run, for the contact sheet.
    std::int64_t total = std::int64_t(overlay.replay().reader().frames().size());
    if (o->max_frames > 0) total = std::min<std::int64_t>(total, o->max_frames);
    std::vector<std::pair<std::int64_t, cv::Mat>> sheet;
    std::int64_t seen = 0;
    overlay.run(o->max_frames, [&](const pipeline::OverlayFrame& f) {
      if (!o->contact_sheet.empty() && int(sheet.size()) < 8 && seen * 7 >= std::int64_t(sheet.size()) * (total - 1))
        sheet.emplace_back(f.index, f.composite.clone());
      ++seen;
      if (video) video->write(f.composite);
      if (frames) frames->write(f.index, f.composite);
      if (auto* w = overlay.window()) {
        w->present(f.composite);
        w->poll_events();
        return !w->should_close();
      }
      return true;
    });
    if (video) video->commit();
    if (frames) frames->commit();
    if (!o->contact_sheet.empty()) pipeline::write_contact_sheet(o->contact_sheet, sheet);
    const auto& stats = overlay.replay().tracker_stats();
    spdlog::info("overlay: {} frames{}{}; tracker: {} records, {} rejected, {} bytes skipped", overlay.times().frames,
                 o->out.empty() ? "" : " -> " + o->out, video ? " (" + video->codec() + ")" : "", stats.records,
                 stats.rejected_records, stats.skipped_bytes);
    if (const auto* lighting = overlay.live_lighting())
      spdlog::info("overlay: lighting scale {:.3f} after {} comparisons of the video with the map", lighting->scale(),
                   lighting->measurements());
    if (overlay.frames_without_pose() > 0)
      spdlog::warn("overlay: {} frames had no tracker pose and show the video alone", overlay.frames_without_pose());
    spdlog::info("{}", pipeline::format_stage_times(overlay.times()));
  });
}

}  // namespace lumar::app
