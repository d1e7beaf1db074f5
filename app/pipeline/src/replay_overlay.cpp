#include "lumar/pipeline/replay_overlay.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <exception>
#include <future>
#include <thread>

#include "lumar/base/error.h"
#include "lumar/render/platform/context.h"
#include "stage_queue.h"

namespace lumar::pipeline {

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// What the pipelined run's stages hand on.
struct Decoded {
  capture::Frame frame;
  Clock::time_point start;  // when its decoding began: the start of its latency
  double decode_ms = 0;
};
struct Prepared {
  Decoded decoded;
  std::optional<FrameLight> light;  // its shadows and light, worked out ahead (Overlay::prepare)
};
struct Composited {
  OverlayFrame frame;
  Clock::time_point start;
};
}  // namespace

ReplayOverlay::ReplayOverlay(const std::filesystem::path& recording, const ReplayOverlaySettings& settings)
    : recording_(recording),
      replay_(recording, settings.filter),
      pose_source_(settings.poses),
      image_aided_(settings.image_aided) {
  if (!replay_.reader().complete() && !settings.allow_incomplete)
    throw InputError(recording.string() + ": incomplete recording (\"complete\": false; its writer was killed, " +
                     "crashed or ran out of disk); its " + std::to_string(replay_.reader().frames().size()) +
                     " closed frames can be replayed with --allow-incomplete");
  const std::filesystem::path scene_path = settings.scene.empty() ? replay_.scene_path() : settings.scene;
  if (scene_path.empty()) throw InputError((recording / "session.json").string() + ": names no scene; pass --scene");
  // The GL driver loads while the scene is read (headless only: a window's toolkit starts
  // on the main thread).
  std::future<void> driver;
  if (!settings.overlay.window) driver = std::async(std::launch::async, gl::load_headless_driver);
  auto scene = std::make_shared<const LoadedScene>(load_scene_files(scene_path));
  if (pose_source_ == PoseSource::Truth && replay_.reader().truth().empty())
    throw InputError(recording.string() + ": has no ground truth (truth.csv); use the tracker's poses");
  const capture::Session& session = replay_.session();
  overlay_ = std::make_unique<Overlay>(std::move(scene), session.camera, session.radiometry,
                                       calib::calibrated_response(session.radiometry, recording), settings.overlay);
  set_pose_source(pose_source_);
  if (settings.auto_quality) choose_quality(*settings.auto_quality);
}

const QualityChoice& ReplayOverlay::choose_quality(const QualityBudget& budget) {
  quality_choice_ = pipeline::choose_quality(*overlay_, probe_frames(budget.frames + 1), budget);
  set_pose_source(pose_source_);  // the fusion starts again with the run's first frame
  return *quality_choice_;
}

std::vector<ProbeFrame> ReplayOverlay::probe_frames(int count) {
  std::vector<ProbeFrame> out;
  const std::size_t total = replay_.reader().frames().size();
  auto frames = replay_.open_frames();
  capture::Frame frame;
  for (std::size_t i = 0; int(out.size()) < count && frames->read(frame); ++i) {
    if (i * std::size_t(count) < out.size() * total) continue;  // before the next one's place
    if (const std::optional<Pose> pose = camera_pose(frame))  // a source may reuse its buffer
      out.push_back({{frame.image.clone(), frame.time, frame.index, frame.chroma}, *pose, shutter_cameras(frame, pose)});
  }
  return out;
}

void ReplayOverlay::set_pose_filter(const std::optional<tracking::PoseFilterSettings>& filter) {
  replay_ = capture::RecordingReplay(recording_, filter);
  set_pose_source(pose_source_);
}

void ReplayOverlay::set_pose_source(PoseSource source) {
  if (source == PoseSource::Truth && replay_.reader().truth().empty())
    throw InputError("this recording has no ground truth (truth.csv); use the tracker's poses");
  if (source == PoseSource::Fused && scene().room.triangle_count() == 0) {
    spdlog::warn(
        "the scene has no proxy room, which the video's corners need for their depth: the tracker's poses "
        "are used as they are");
    source = PoseSource::Tracker;
  }
  pose_source_ = source;
  fused_.reset();
  if (source == PoseSource::Fused)
    fused_ = std::make_unique<ImageAidedPose>(replay_.session().camera, scene().room, image_aided_,
                                              overlay_->room_prediction());
}

std::optional<Pose> ReplayOverlay::camera_pose(const capture::Frame& frame) {
  if (pose_source_ == PoseSource::Truth) return replay_.true_camera_pose(frame.index);
  const std::optional<Pose> tracked = replay_.tracked_camera_pose(frame.time);
  return fused_ ? fused_->update(frame, tracked) : tracked;
}

std::vector<std::optional<Pose>> ReplayOverlay::shutter_cameras(const capture::Frame& frame,
                                                               const std::optional<Pose>& pose) const {
  if (pose_source_ != PoseSource::Truth)
    return overlay_->shutter_cameras(frame.time, pose, [&](Nanos t) { return replay_.tracked_camera_pose(t); });
  const std::vector<Nanos> times = overlay_->shutter_times(frame.time);
  if (!pose || times.empty()) return {};
  std::vector<std::optional<Pose>> out;
  for (const Nanos t : times)  // the frame's own pose bit for bit: the renderer draws that instant once
    out.push_back(t == frame.time ? pose : replay_.true_camera_pose_at(t));
  return out;
}

void ReplayOverlay::run(int max_frames, const std::function<bool(const OverlayFrame&)>& sink, bool pipelined) {
  if (pipelined) return run_pipelined(max_frames, sink);
  auto frames = replay_.open_frames();
  StageTimes& times = overlay_->times();
  capture::Frame frame;
  for (int n = 0; max_frames <= 0 || n < max_frames; ++n) {
    const auto start = Clock::now();
    auto t0 = start;
    if (!frames->read(frame)) break;
    times.decode += ms_since(t0);

    t0 = Clock::now();
    const std::optional<Pose> pose = camera_pose(frame);
    const std::vector<std::optional<Pose>> shutter = shutter_cameras(frame, pose);
    times.pose += ms_since(t0);

    const OverlayFrame out = overlay_->composite(frame, pose, shutter);
    t0 = Clock::now();
    const bool go_on = sink(out);
    times.output += ms_since(t0);
    times.latency += ms_since(start);
    if (!go_on) break;
  }
}

void ReplayOverlay::run_pipelined(int max_frames, const std::function<bool(const OverlayFrame&)>& sink) {
  // Closing a queue ends the stream through it: the producer ran out, or a consumer stopped.
  // With the lighting fixed, a fourth thread works out each frame's shadows and light
  // (Overlay::prepare) while the frame before is drawn.
  const bool ahead = overlay_->can_prepare_ahead();
  StageQueue<Decoded> decoded(kPipelineDepth);
  StageQueue<Prepared> prepared(kPipelineDepth);
  StageQueue<Composited> composited(kPipelineDepth);
  const auto close_all = [&] {
    decoded.close();
    prepared.close();
    composited.close();
  };
  std::exception_ptr decode_error, prepare_error, sink_error;
  double output_ms = 0, latency_ms = 0;  // the sink thread's, added to the times once it joined

  std::thread decoder([&, frames = replay_.open_frames()] {
    try {
      for (int n = 0; (max_frames <= 0 || n < max_frames) && decoded.wait_for_room(); ++n) {
        Decoded d;
        d.start = Clock::now();
        if (!frames->read(d.frame)) break;
        d.decode_ms = ms_since(d.start);
        if (!decoded.push(std::move(d))) break;
      }
    } catch (...) {
      decode_error = std::current_exception();
    }
    decoded.close();
  });
  std::thread preparer([&] {
    if (!ahead) return;
    try {
      for (Decoded d; decoded.pop(d);) {
        FrameLight light = overlay_->prepare(d.frame.time);
        if (!prepared.push(Prepared{std::move(d), std::move(light)})) break;
      }
    } catch (...) {
      prepare_error = std::current_exception();
    }
    prepared.close();
    decoded.close();
  });
  std::thread writer([&] {
    try {
      for (Composited c; composited.pop(c);) {
        const auto t0 = Clock::now();
        const bool go_on = sink(c.frame);
        output_ms += ms_since(t0);
        latency_ms += ms_since(c.start);
        if (!go_on) break;
      }
    } catch (...) {
      sink_error = std::current_exception();
    }
    close_all();  // the other stages stop at their next push or pop
  });
  StageTimes& times = overlay_->times();
  std::exception_ptr composite_error;
  try {
    // The next frame, prepared ahead or not.
    const auto next = [&](Prepared& p) {
      if (ahead) return prepared.pop(p);
      p.light.reset();
      return decoded.pop(p.decoded);
    };
    for (Prepared p; next(p);) {
      times.decode += p.decoded.decode_ms;
      const auto t0 = Clock::now();
      const std::optional<Pose> pose = camera_pose(p.decoded.frame);
      const std::vector<std::optional<Pose>> shutter = shutter_cameras(p.decoded.frame, pose);
      times.pose += ms_since(t0);
      OverlayFrame out = p.light ? overlay_->render(p.decoded.frame, pose, *p.light, shutter)
                                 : overlay_->composite(p.decoded.frame, pose, shutter);
      if (!composited.push(Composited{std::move(out), p.decoded.start})) break;
    }
  } catch (...) {
    composite_error = std::current_exception();
  }
  close_all();
  decoder.join();
  preparer.join();
  writer.join();
  // A frame prepared ahead may have been dropped when the run stopped.
  if (ahead) overlay_->compositor().forget_prepared();
  times.output += output_ms;
  times.latency += latency_ms;
  for (const std::exception_ptr& e : {composite_error, prepare_error, sink_error, decode_error})
    if (e) std::rethrow_exception(e);
}

}  // namespace lumar::pipeline
