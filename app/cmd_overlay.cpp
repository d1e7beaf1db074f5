// lumar overlay: composite the scene's virtual objects into a recording's video
// (pipeline/replay_overlay.h), or live into a camera's (pipeline/live_overlay.h).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>
#include <optional>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/base/stop_signal.h"
#include "lumar/pipeline/live_overlay.h"
#include "lumar/pipeline/output_files.h"
#include "lumar/pipeline/progress.h"
#include "lumar/pipeline/replay_overlay.h"
#include "lumar/ui/overlay_window.h"

namespace lumar::app {

namespace {

struct OverlayOptions {
  std::string recording, scene, out, frames_dir, contact_sheet, poses = "fused", undistort = "same";
  std::string filter = "none";
  CompositeOptions composite;
  bool window = false, no_cache = false, allow_incomplete = false, paused = false, serial = false;
  std::string save_scene, screenshot, stats_json;
  int max_frames = 0;
  int adapt_lighting = 0, adapt_lighting_cells = 32;
  pipeline::ImageAidedSettings image_aided;  // --poses fused
  pipeline::LiveOverlayOptions live;         // --source and what only the live path reads
};

pipeline::OverlaySettings overlay_settings(const OverlayOptions& o, bool window) {
  pipeline::OverlaySettings s;
  s.undistortion = o.undistort == "crop"   ? calib::UndistortedCamera::CropToValid
                   : o.undistort == "keep" ? calib::UndistortedCamera::KeepAll
                                           : calib::UndistortedCamera::SameMatrix;
  s.adapt_lighting_every = o.adapt_lighting;
  s.adapt_lighting_cells = o.adapt_lighting_cells;
  s.window = window;
  s.volume_cache = !o.no_cache;
  apply_composite_options(o.composite, s);
  return s;
}

// Writes every frame to the outputs (the headless paths; a window has its own loop).
auto frame_sink(pipeline::OverlayOutputs& outputs) {
  return [&](const pipeline::OverlayFrame& f) {
    outputs.write(f.index, f.composite);
    return true;
  };
}

ui::OverlayWindowSettings window_settings(const OverlayOptions& o, const pipeline::Overlay& overlay) {
  ui::OverlayWindowSettings w;
  w.save_scene = !o.save_scene.empty()
                     ? std::filesystem::path(o.save_scene)
                     : std::filesystem::path(overlay.scene().manifest.manifest.stem().string() + "-edited.json");
  if (!o.screenshot.empty()) w.screenshot = o.screenshot;
  w.paused = o.paused;
  w.pose_filter = o.filter != "none";
  w.max_frames = o.max_frames;
  return w;
}

// --stats-json: the run's figures, for tools (docs/formats.md, "Overlay stats"). `started`:
// when the command began (before the scene was read), `t0` when the frames began.
void write_stats(const OverlayOptions& o, const pipeline::Overlay& overlay,
                 std::chrono::steady_clock::time_point started, std::chrono::steady_clock::time_point t0) {
  const auto first = overlay.first_composite_time();
  const double startup_ms = first ? std::chrono::duration<double, std::milli>(*first - started).count() : -1.0;
  if (first) spdlog::info("overlay: first frame composited {:.0f} ms after the command started", startup_ms);
  if (o.stats_json.empty()) return;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_file_atomically(o.stats_json,
                        pipeline::stage_times_json(overlay.times(), wall, startup_ms, overlay.quality().describe()));
}

void report(const pipeline::Overlay& overlay) {
  if (const auto* lighting = overlay.live_lighting())
    spdlog::info(
        "overlay: lighting scale {:.3f} after {} comparisons of the video with the map: {} of {} map cells seen, "
        "{} re-bakes (the last {:.0f} ms)",
        lighting->scale(), lighting->measurements(), lighting->adapter().measured_cells(),
        lighting->adapter().settings().cell_cols * lighting->adapter().settings().cell_rows, lighting->bakes(),
        lighting->last_bake_ms());
  if (overlay.frames_without_pose() > 0)
    spdlog::warn("overlay: {} frames had no tracker pose and show the video alone", overlay.frames_without_pose());
  spdlog::info("{}", pipeline::format_stage_times(overlay.times()));
}

void run_live(OverlayOptions& o) {
  const auto started = std::chrono::steady_clock::now();
  if (!o.recording.empty()) throw InputError("overlay: give --recording or --source, not both");
  if (!o.contact_sheet.empty()) throw InputError("--contact-sheet: a live run has no known length; use --frames-dir");
  if (o.poses == "truth") throw InputError("--poses truth: a live source has no ground truth");
  o.live.steady_with_video = o.poses == "fused";
  o.live.image_aided = o.image_aided;
  pipeline::LiveOverlayOptions& live = o.live;
  live.scene = o.scene;
  live.max_frames = o.max_frames;
  live.filter = tracking::parse_pose_filter(o.filter);
  // A window unless the frames go to files only.
  const bool window = o.window || (o.out.empty() && o.frames_dir.empty());
  live.overlay = overlay_settings(o, window);
  live.auto_quality = auto_quality(o.composite);  // on the camera's first frames
  live.overlay.window_title = "lumar overlay (live)";
  if (window) live.overlay.window_panel_width = ui::kPanelWidth;
  pipeline::LiveOverlay overlay(live);
  const auto& camera = overlay.overlay().compositor().output_camera();
  pipeline::OverlayOutputs outputs({o.out, o.frames_dir, "", overlay.fps(), cv::Size(camera.width, camera.height)});
  const auto t0 = std::chrono::steady_clock::now();
  if (window) {  // the panels, and the camera's and tracker's status
    ui::run_live_overlay_window(overlay, window_settings(o, overlay.overlay()),
                                [&](const pipeline::OverlayFrame& f) { outputs.write(f.index, f.composite); });
  } else {
    overlay.run(frame_sink(outputs));
  }
  outputs.commit();
  write_stats(o, overlay.overlay(), started, t0);
  report(overlay.overlay());
}

void run_replay(const OverlayOptions& o) {
  const auto started = std::chrono::steady_clock::now();
  if (o.recording.empty()) throw InputError("overlay: give --recording DIR, or --source SPEC for the live path");
  if (o.out.empty() && o.frames_dir.empty() && o.contact_sheet.empty() && !o.window && o.stats_json.empty())
    throw InputError("overlay: nothing to do; give --out, --frames-dir, --contact-sheet, --stats-json or --window");
  if (!o.live.rig.empty() || o.live.response || o.live.vignetting_a || o.live.vignetting_b || o.live.exposure)
    throw InputError(
        "overlay --recording: --rig, --response, --vignetting and --exposure are for --source; a "
        "recording's session.json already says them");
  pipeline::ReplayOverlaySettings settings;
  settings.scene = o.scene;
  settings.poses = o.poses == "truth"   ? pipeline::PoseSource::Truth
                   : o.poses == "fused" ? pipeline::PoseSource::Fused
                                        : pipeline::PoseSource::Tracker;
  settings.filter = tracking::parse_pose_filter(o.filter);
  settings.image_aided = o.image_aided;
  settings.allow_incomplete = o.allow_incomplete;
  settings.overlay = overlay_settings(o, o.window);
  settings.auto_quality = auto_quality(o.composite);
  if (o.window) settings.overlay.window_panel_width = ui::kPanelWidth;
  pipeline::ReplayOverlay overlay(o.recording, settings);
  const auto& camera = overlay.compositor().output_camera();
  std::int64_t total = std::int64_t(overlay.replay().reader().frames().size());
  if (total == 0)  // an empty video would look like a result
    throw InputError(o.recording + ": has no frames to composite (frames.csv lists none)");
  if (const auto& loss = overlay.replay().tracker_loss(); !loss.empty()) spdlog::warn("{}", loss);
  if (o.max_frames > 0) total = std::min<std::int64_t>(total, o.max_frames);
  catch_stop_signals();  // from here on Ctrl-C stops between frames, and nothing is committed
  pipeline::OverlayOutputs outputs({o.out, o.frames_dir, o.contact_sheet, overlay.replay().reader().video().fps,
                                    cv::Size(camera.width, camera.height), total});
  pipeline::Progress progress("overlay", int(total), "frames", true);  // on a terminal only
  int done = 0;
  const auto t0 = std::chrono::steady_clock::now();
  if (o.window) {  // interactive: the window's transport plays, edits and seeks
    ui::run_overlay_window(overlay, window_settings(o, overlay.overlay()), [&](const pipeline::OverlayFrame& f) {
      if (done < total) outputs.write(f.index, f.composite);
      ++done;
    });
    if (stop_requested())
      throw Interrupted(fmt::format("overlay: stopped after {} frames had played; no output written", done));
    if (done < total && !(o.out.empty() && o.frames_dir.empty() && o.contact_sheet.empty()))
      throw Interrupted(
          fmt::format("overlay: the window closed after {} of {} frames had played; no output written", done, total));
  } else {
    auto sink = frame_sink(outputs);
    // Pipelined, the sink (encoding, files) runs on its own thread (ReplayOverlay::run).
    overlay.run(
        o.max_frames,
        [&](const pipeline::OverlayFrame& f) {
          const bool go_on = sink(f);
          progress.update(++done);
          return go_on && !stop_requested();
        },
        !o.serial);
  }
  progress.finish();
  if (stop_requested())
    throw Interrupted(fmt::format("overlay: after {} of {} frames; no output written", done, total));
  outputs.commit();
  write_stats(o, overlay.overlay(), started, t0);
  const auto& stats = overlay.replay().tracker_stats();
  spdlog::info("overlay: {} frames{}; tracker: {} records, {} rejected, {} of {} bytes lost", overlay.times().frames,
               outputs.describe(), stats.records, stats.rejected_records, stats.lost_bytes(), stats.stream_bytes);
  report(overlay.overlay());
}

}  // namespace

void register_overlay(CLI::App& app) {
  auto o = std::make_shared<OverlayOptions>();
  auto* cmd = app.add_subcommand(
      "overlay",
      "Composite virtual objects into a recording's video, or live into a camera's (headless or in a window)");
  cmd->add_option("--recording", o->recording, "Recording directory (video + tracker stream + session.json)");
  cmd->add_option("--scene", o->scene, "Scene manifest; default: the one the recording's session names");
  cmd->add_option("--out", o->out, "Output video (.mp4, .mkv or .avi)");
  cmd->add_option("--frames-dir", o->frames_dir, "Also write every output frame as PNG into this new folder");
  cmd->add_option("--contact-sheet", o->contact_sheet, "Also write 8 frames spread over the run, tiled, as one PNG");
  cmd->add_option("--poses", o->poses,
                  "Camera poses: the tracker stream steadied by the video (fused, the default), the tracker stream "
                  "alone, or the recording's "
                  "ground truth")
      ->check(CLI::IsMember({"tracker", "fused", "truth"}))
      ->capture_default_str();
  cmd->add_option("--tracker-gain", o->image_aided.fusion.tracker_gain,
                  "--poses fused: how much each frame's fused pose moves towards the tracker's, in (0, 1] (lower: "
                  "steadier, slower to leave the video's drift; docs/tracker.md)")
      ->capture_default_str();
  cmd->add_option("--align-every", o->image_aided.align_every,
                  "--poses fused: frames between absolute fixes, each the frame aligned with the room the proxy "
                  "and the map predict (0: only at the start and after a gap)")
      ->capture_default_str();
  cmd->add_option("--fix-worth", o->image_aided.fusion.fix_worth,
                  "--poses fused: how many tracker samples one absolute fix is worth (0: no fixes)")
      ->capture_default_str();
  cmd->add_option("--filter", o->filter,
                  "Pose filter on the tracker's samples: none, one-euro (the setting the filter benchmark chose: "
                  "docs/tracker_filter_jitter_vs_lag.png) or one-euro:MIN_CUTOFF_HZ,BETA")
      ->capture_default_str();
  cmd->add_option(
         "--undistort", o->undistort,
         "Output camera: 'same' keeps the calibrated matrix, 'crop' shows only valid pixels, 'keep' every input pixel")
      ->check(CLI::IsMember({"same", "crop", "keep"}))
      ->capture_default_str();
  cmd->add_option(
         "--adapt-lighting", o->adapt_lighting,
         "Every N frames, compare the video with the map and follow the room's light per direction and colour: a "
         "lamp going out, a window turning warmer (0 = off; docs/envmap.md)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--adapt-lighting-cells", o->adapt_lighting_cells,
                  "--adapt-lighting: the map's directions in this many columns of cells, half as many rows "
                  "(docs/lighting_change_error_vs_time.png)")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd->add_flag("--window", o->window,
                "Show the result in a window (needs a display): a recording's with panels to play it and to place, "
                "add and light objects (docs/interactive.md); the live path shows one unless it writes files");
  cmd->add_option("--save-scene", o->save_scene,
                  "Window: where File > Save (Ctrl+S) writes the edited scene (default: SCENE-edited.json here)");
  cmd->add_option("--screenshot", o->screenshot,
                  "Window: where File > Screenshot (F12; Ctrl+F12 with the panels) writes (default: "
                  "lumar-screenshot.png here)");
  cmd->add_flag("--paused", o->paused, "Window: start paused on the first frame");
  cmd->add_option("--stats-json", o->stats_json,
                  "Write the run's figures as JSON: frames, fps, latency_ms_mean, stages (ms per frame); with it "
                  "--out may be left out, to composite without encoding");
  cmd->add_flag("--allow-incomplete", o->allow_incomplete,
                "Replay a recording that was never closed (killed or crashed): its closed frames");
  cmd->add_option("--max-frames", o->max_frames, "Stop after this many frames (0 = all)")->capture_default_str();
  add_composite_options(cmd, o->composite);
  cmd->add_flag("--no-cache", o->no_cache,
                "Build the irradiance volume and the shadow lines without reading or writing the cache "
                "($XDG_CACHE_HOME/lumar)");
  cmd->add_flag("--serial", o->serial,
                "A recording without a window: decode, composite and write each frame one after another on one "
                "thread, instead of the three stages on their own threads (the baseline the pipeline is measured "
                "against; docs/results.md)");
  // The live path (pipeline/live_overlay.h): --source and --tracker instead of --recording.
  pipeline::LiveOverlayOptions& live = o->live;
  cmd->add_option("--source", live.in.source, "Live: video:FILE, images:DIR, v4l2:/dev/videoN or recording:DIR");
  cmd->add_option("--rig", live.rig,
                  "Live: a session.json whose rig, camera calibration and radiometry to use (flags override them)");
  cmd->add_option("--response", live.response, "Live: camera response JSON, or srgb (default: the --rig session's)");
  cmd->add_option("--vignetting", live.vignetting_a, "Live: vignetting gain 1 + a r^2 + b r^4, the a term");
  cmd->add_option("--vignetting-b", live.vignetting_b, "Live: vignetting, the b term");
  cmd->add_option("--exposure", live.exposure, "Live: video linear value per unit radiance (default: the session's)");
  cmd->add_option("--max-wait-ms", live.max_wait_ms, "Live: longest a frame waits for the tracker's pose")
      ->capture_default_str();
  add_live_input_options(cmd, live.in);
  add_action(cmd, [o] {
    if (!o->live.in.source.empty()) return run_live(*o);
    run_replay(*o);
  });
}

}  // namespace lumar::app
