#include "lumar/pipeline/live_overlay.h"

#include <spdlog/spdlog.h>

#include <thread>

#include "lumar/base/error.h"
#include "lumar/calib/undistortion.h"
#include "lumar/capture/capture_thread.h"
#include "lumar/capture/frame_pose_pairing.h"
#include "lumar/pipeline/stop_signal.h"
#include "lumar/render/compositor.h"
#include "lumar/render/platform/context.h"
#include "lumar/scene/loaded_scene.h"

namespace lumar::pipeline {

void run_live_overlay(const LiveOverlayOptions& o) {
  if (o.scene.empty()) throw InputError("overlay: the live path needs --scene");
  const auto scene = std::make_shared<const LoadedScene>(load_scene_files(o.scene));
  const tracking::Rig rig = live_rig(o.rig.string(), o.in.latency_ms);
  LiveSource live = open_live_source(o.in);
  const cv::Size size = live.source->frame_size();
  const CameraIntrinsics camera = live_camera(o.in, size.width, size.height);

  capture::FramePosePairing pairing(rig);
  auto driver = make_tracker_driver(o.in, {});
  gl::WindowContext window(camera.width, camera.height, "lumar overlay (live)");
  const calib::UndistortionMaps maps = calib::make_undistortion_maps(camera);
  Compositor compositor(scene, maps.output, maps.map_x, maps.map_y);

  catch_stop_signals();
  if (driver) driver->start();
  capture::FrameQueue queue(1, capture::QueuePolicy::KeepNewest);  // always the freshest picture
  capture::CaptureThread capture(std::move(live.source), queue);
  std::vector<tracking::PoseSample> samples;
  std::uint64_t frames = 0, without_pose = 0, extrapolated = 0;
  const Nanos max_wait = seconds_to_nanos(o.max_wait_ms * 1e-3);
  while (!stop_requested() && !window.should_close() && (o.max_frames <= 0 || int(frames) < o.max_frames)) {
    window.poll_events();
    capture::Frame frame;
    if (!queue.pop(frame, 50'000'000)) {
      if (queue.closed()) break;
      continue;
    }
    // Hold the frame briefly until the tracker has a sample past its time: then the
    // pose is interpolated, not extrapolated.
    const Nanos deadline = monotonic_now() + max_wait;
    for (;;) {
      if (driver) {
        samples.clear();
        driver->take_samples(samples);
        pairing.add(samples);
      }
      if (!driver || pairing.covers(frame.time) || monotonic_now() >= deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    const capture::PairedFrame paired = pairing.pair(std::move(frame));
    if (!paired.T_world_camera) ++without_pose;
    if (paired.sensor.status == tracking::PoseStatus::Extrapolated) ++extrapolated;
    window.present(compositor.composite(paired.frame.image, paired.T_world_camera, o.exposure, nullptr));
    ++frames;
    if (frames % 300 == 0) pairing.forget_before(paired.frame.time - kNanosPerSecond);
  }
  capture.stop();
  if (driver) driver->stop();
  const auto qs = queue.stats();
  spdlog::info("overlay: {} frames shown, {} stale frames skipped, {} without a pose, {} extrapolated", frames,
               qs.stale_dropped, without_pose, extrapolated);
  if (capture.end() == capture::CaptureEnd::Vanished || capture.end() == capture::CaptureEnd::Failed) {
    if (capture.input_error()) throw InputError(capture.message());
    throw RuntimeError(capture.message());
  }
}

}  // namespace lumar::pipeline
