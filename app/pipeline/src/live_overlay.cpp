#include "lumar/pipeline/live_overlay.h"

#include <spdlog/spdlog.h>

#include <chrono>

#include "lumar/base/error.h"
#include "lumar/capture/session.h"

namespace lumar::pipeline {

LiveOverlay::LiveOverlay(const LiveOverlayOptions& o) {
  if (o.scene.empty()) throw InputError("overlay: the live path needs --scene");
  auto scene = std::make_shared<const LoadedScene>(load_scene_files(o.scene));

  // The session that describes the camera: --rig's, else a recording source's own.
  std::optional<capture::Session> session;
  std::filesystem::path session_dir;
  if (!o.rig.empty()) {
    session = capture::load_session_file(o.rig);
    session_dir = o.rig.parent_path();
  } else if (o.in.source.rfind("recording:", 0) == 0) {
    session_dir = o.in.source.substr(std::string("recording:").size());
    session = capture::load_session_file(session_dir / "session.json");
  }

  LiveInputOptions in = o.in;
  if (session && in.latency_ms == 0) in.latency_ms = nanos_to_seconds(session->rig.latency) * 1e3;
  LiveSource live = open_live_source(in);
  fps_ = live.source->nominal_fps() > 0 ? live.source->nominal_fps() : 30.0;
  const cv::Size size = live.source->frame_size();
  CameraIntrinsics camera = live_camera(in, size.width, size.height);
  if (in.camera_file.empty() && session && session->camera.width == size.width && session->camera.height == size.height)
    camera = session->camera;

  capture::Radiometry radiometry = session ? session->radiometry : capture::Radiometry{};
  std::optional<calib::CameraResponse> response;
  if (o.response) {
    radiometry.response = *o.response;
    response = calib::calibrated_response(radiometry, std::filesystem::current_path());
  } else if (session) {
    response = calib::calibrated_response(radiometry, session_dir);
  }
  if (o.vignetting_a) radiometry.vignetting_a = *o.vignetting_a;
  if (o.vignetting_b) radiometry.vignetting_b = *o.vignetting_b;
  if (o.exposure) radiometry.exposure = *o.exposure;
  if (!(radiometry.exposure > 0)) throw InputError("--exposure must be a positive number");
  // The camera's own exposure time, where it says it, is the shutter the motion blur
  // spans (--shutter overrides it); else the session's.
  if (const double shutter_s = source_shutter_s(*live.source); shutter_s > 0) radiometry.shutter_s = shutter_s;

  tracking::Rig rig = session ? session->rig : tracking::Rig{};
  rig.latency = seconds_to_nanos(in.latency_ms * 1e-3);
  auto driver = make_tracker_driver(in, {});
  const auto recorded = recorded_poses_of(in);

  OverlaySettings overlay = o.overlay;
  overlay.live = true;  // paths play from the first frame
  overlay_ = std::make_unique<Overlay>(std::move(scene), camera, radiometry, response, overlay);
  LiveLoopSettings settings;
  settings.what = "overlay";
  settings.policy = capture::QueuePolicy::KeepNewest;  // always the freshest picture
  settings.queue_frames = 1;
  settings.max_wait = seconds_to_nanos(o.max_wait_ms * 1e-3);
  settings.max_frames = o.max_frames;
  settings.filter = o.filter;
  // With motion blur, a frame waits for the tracker to pass its shutter's end, not only its middle.
  if (!overlay_->shutter_times(0).empty()) settings.shutter = seconds_to_nanos(overlay_->shutter_s());
  loop_ = std::make_unique<LiveLoop>(std::move(live.source), std::move(driver), rig, settings);
  if (o.steady_with_video) {
    if (overlay_->scene().room.triangle_count() > 0)
      fused_ =
          std::make_unique<ImageAidedPose>(camera, overlay_->scene().room, o.image_aided, overlay_->room_prediction());
    else
      spdlog::warn(
          "the scene has no proxy room, which the video's corners need for their depth: the tracker's "
          "poses are used as they are");
  }
  if (recorded) loop_->use_recorded_poses(recorded);
  if (o.auto_quality) choose_quality(*o.auto_quality);
}

void LiveOverlay::choose_quality(const QualityBudget& budget) {
  if (budget.frames < 1) throw InputError("quality auto: needs at least one timed frame");
  probe_budget_ = budget;
  probes_.clear();
  spdlog::info("quality auto: choosing on the next {} frames with a pose, {:.1f} s apart", budget.frames + 1,
               kProbeSpacingS);
}

std::pair<int, int> LiveOverlay::quality_probes() const {
  return probe_budget_ ? std::pair{int(probes_.size()), probe_budget_->frames + 1} : std::pair{0, 0};
}

bool LiveOverlay::probe(const capture::Frame& frame, const std::optional<Pose>& pose,
                        const std::vector<std::optional<Pose>>& shutter_cameras) {
  if (!probe_budget_ || !pose) return false;
  if (!probes_.empty() && nanos_to_seconds(frame.time - probes_.back().frame.time) < kProbeSpacingS) return false;
  probes_.push_back({{frame.image.clone(), frame.time, frame.index, frame.chroma}, *pose, shutter_cameras});  // the source reuses its buffer
  if (int(probes_.size()) < probe_budget_->frames + 1) return false;
  const QualityBudget budget = *probe_budget_;
  probe_budget_.reset();
  quality_choice_ = pipeline::choose_quality(*overlay_, probes_, budget);
  probes_.clear();
  return true;
}

void LiveOverlay::run(const std::function<bool(const OverlayFrame&)>& sink) {
  StageTimes& times = overlay_->times();
  loop_->run(
      [&](capture::PairedFrame& paired) {
        auto t0 = std::chrono::steady_clock::now();
        const std::optional<Pose> pose =
            fused_ ? fused_->update(paired.frame, paired.T_world_camera) : paired.T_world_camera;
        times.pose += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        // The frame a choice was made on waited for it: the stage times start after it.
        const auto first_composite = overlay_->first_composite_time();
        const std::vector<std::optional<Pose>> shutter = overlay_->shutter_cameras(
            paired.frame.time, pose, [&](Nanos t) { return loop_->camera_at(paired.frame, t); });
        const bool chose = probe(paired.frame, pose, shutter);
        const OverlayFrame out = overlay_->composite(paired.frame, pose, shutter);
        t0 = std::chrono::steady_clock::now();
        const bool go_on = sink(out);
        times.output += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        times.latency += nanos_to_seconds(monotonic_now() - paired.frame.time) * 1e3;  // capture to handed on
        if (chose) overlay_->reset_times(first_composite);
        return go_on;
      },
      [&] {
        if (auto* w = overlay_->window()) {
          w->poll_events();
          return !w->should_close();
        }
        return true;
      });
  if (const auto [have, need] = quality_probes(); need > 0)
    spdlog::warn(
        "quality auto: the source ended with {} of the {} frames with a pose a choice needs; the quality "
        "stayed as given",
        have, need);
  const auto& s = loop_->stats();
  spdlog::info("overlay: {} frames shown, {} stale frames skipped, {} without a pose, {} extrapolated", s.frames,
               s.queue.stale_dropped, s.without_pose, s.extrapolated);
  loop_->check_source();
}

}  // namespace lumar::pipeline
