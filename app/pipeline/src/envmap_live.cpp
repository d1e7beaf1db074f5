#include "lumar/pipeline/envmap_live.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <map>
#include <optional>
#include <thread>

#include "lumar/base/error.h"
#include "lumar/calib/camera_response.h"
#include "lumar/capture/capture_thread.h"
#include "lumar/capture/frame_pose_pairing.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/stop_signal.h"

namespace lumar::pipeline {

namespace {

// The recording behind `recording:DIR`, whose own tracker stream pairs its frames.
std::optional<capture::RecordingReplay> recording_of(const LiveInputOptions& in) {
  const std::string prefix = "recording:";
  if (!in.tracker.empty() || in.source.rfind(prefix, 0) != 0) return std::nullopt;
  return std::make_optional<capture::RecordingReplay>(in.source.substr(prefix.size()));
}

// Percentage of map pixels seen by at least one frame.
double covered_percent(const calib::EnvmapStitcher& stitcher) {
  const cv::Mat c = stitcher.coverage();
  return 100.0 * cv::countNonZero(c) / double(c.total());
}

}  // namespace

void run_live_envmap(const LiveEnvmapOptions& o) {
  check_map_width(o.out.width);
  if (!(o.update_every_s > 0)) throw InputError("--update-every must be a positive number of seconds");
  if (o.exposures.empty()) throw InputError("--frame-exposure needs at least one value");
  for (double e : o.exposures)
    if (!(e > 0) || !std::isfinite(e)) throw InputError("--frame-exposure: every value must be a positive number");
  if (o.refine_at_end && o.keep_frames < 1) throw InputError("--keep-frames must be at least 1");
  if (!(o.tracker_timeout_s > 0)) throw InputError("--tracker-timeout must be a positive number of seconds");
  if (!(o.duration_s >= 0)) throw InputError("--duration must be 0 or more seconds");
  const std::optional<capture::RecordingReplay> replay = recording_of(o.in);
  if (o.in.tracker.empty() && !replay)
    throw InputError("envmap --source " + o.in.source +
                     ": a live sweep needs --tracker serial:PORT (only a recording:DIR brings its own poses)");
  if (replay && replay->tracker_stats().records == 0)
    throw InputError(o.in.source + ": the recording has no tracker poses; a sweep needs the tracker's stream");

  LiveSource live = open_live_source(o.in);
  const cv::Size size = live.source->frame_size();
  calib::StitchSettings st;
  st.width = o.out.width;
  std::vector<double> exposures = o.exposures;
  std::map<std::int64_t, Nanos> recorded_time;  // recording: frame index -> its time in the recording
  std::string reference = o.out.reference;      // a synthetic recording's source map by default
  // --refine-at-end: the frames kept, with what the offline pipeline needs of each.
  SweepInput kept;
  kept.name = o.in.source;
  kept.label_header = "index,time_ns";
  kept.tracker_noise_deg = o.tracker_noise_deg;
  std::vector<cv::Mat> kept_frames;
  bool kept_all = true;
  bool bracket = false;  // a recording's brackets: frames taken standing still share a rotation
  if (replay) {
    const capture::Session& session = replay->session();
    st.camera = o.in.camera_file.empty() ? session.camera : live_camera(o.in, size.width, size.height);
    if (st.camera.width != size.width || st.camera.height != size.height)
      throw InputError(o.in.source + ": the session's calibration does not match the frames' size; give --camera");
    const auto dir = std::filesystem::path(o.in.source.substr(std::string("recording:").size()));
    st.response = calib::calibrated_response(session.radiometry, dir).value_or(calib::srgb_response(1.0));
    st.vignetting_a = session.radiometry.vignetting_a;
    st.vignetting_b = session.radiometry.vignetting_b;
    exposures =
        session.frame_exposures.empty() ? std::vector<double>{session.radiometry.exposure} : session.frame_exposures;
    for (const auto& f : replay->reader().frames()) recorded_time[f.index] = f.time;
    bracket = session.exposure_bracket;
    if (session.synth) kept.tracker_noise_deg = session.synth->tracker_noise_deg;
    if (session.envmap) {
      st.azimuth_offset_deg = session.envmap->azimuth_offset_deg;
      const std::string& source_map = session.envmap->source_map;
      if (std::error_code ec; reference.empty() && !source_map.empty() && std::filesystem::exists(source_map, ec))
        reference = source_map;
    }
  } else {
    st.camera = live_camera(o.in, size.width, size.height);
    st.response = o.response.empty() ? calib::srgb_response(1.0) : calib::load_camera_response(o.response);
    st.vignetting_a = o.vignetting_a;
    st.vignetting_b = o.vignetting_b;
  }
  if (o.out.azimuth_offset_deg) st.azimuth_offset_deg = *o.out.azimuth_offset_deg;
  calib::EnvmapStitcher stitcher(st);

  capture::FramePosePairing pairing(live_rig(o.rig, o.in.latency_ms));
  auto driver = make_tracker_driver(o.in, {});
  std::vector<tracking::PoseSample> samples;
  catch_stop_signals();
  if (driver) {
    // A frame without a pose is lost to the map: start the camera once poses flow.
    driver->start();
    const Nanos give_up = monotonic_now() + seconds_to_nanos(o.tracker_timeout_s);
    while (pairing.samples() == 0 && !stop_requested()) {
      if (monotonic_now() >= give_up) {
        const std::string why = driver->status().message;
        driver->stop();
        throw InputError(o.in.tracker + ": no pose from the tracker within " +
                         std::to_string(int(o.tracker_timeout_s)) + " s (" + (why.empty() ? "no answer" : why) +
                         "); check that it is on, the port, --tracker-device and --baud");
      }
      samples.clear();
      driver->take_samples(samples);
      pairing.add(samples);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  if (!replay && o.in.camera_file.empty())
    spdlog::warn("envmap: no --camera; assuming a pinhole with focal length {} px and no distortion", size.width);
  // A camera cannot wait: keep the newest frames. A file can: stitch every frame.
  capture::FrameQueue queue(4, live.camera ? capture::QueuePolicy::KeepNewest : capture::QueuePolicy::KeepAll);
  capture::CaptureThread capture(std::move(live.source), queue);

  const Nanos start = monotonic_now();
  const Nanos end = o.duration_s > 0 ? start + seconds_to_nanos(o.duration_s) : 0;
  const Nanos update_every = seconds_to_nanos(o.update_every_s);
  const Nanos max_wait = seconds_to_nanos(o.max_wait_ms * 1e-3);
  Nanos next_update = start + update_every, next_progress = start + kNanosPerSecond;
  std::uint64_t frames = 0, without_pose = 0, updates = 0;
  glm::dvec3 position_sum(0.0);
  bool tracker_ok = true;  // the tracker delivered its first pose before the capture started

  int written = 0, reported = -1;  // frames in the last written / reported map
  auto write_now = [&] {
    if (stitcher.frames_added() == written) return;
    written = stitcher.frames_added();
    EnvironmentMap map = stitcher.current_map();
    map.capture_position = position_sum / double(stitcher.frames_added());
    write_envmap_outputs(std::move(map), stitcher.coverage(), o.out);
    ++updates;
    spdlog::info("envmap: updated {} ({} frames stitched, {:.1f} % covered)", o.out.out, stitcher.frames_added(),
                 covered_percent(stitcher));
  };

  while (!stop_requested() && (end == 0 || monotonic_now() < end)) {
    if (driver) {
      // One line when the tracker stops delivering (unplugged, silent, resetting) and one
      // when it is back, not one per frame or per reset attempt.
      const auto status = driver->status();
      const bool connected = status.state == tracking::TrackerState::connected;
      if (connected != tracker_ok) {
        if (!connected)
          spdlog::warn("envmap: tracker lost ({}); frames are not stitched until it is back", status.message);
        else
          spdlog::info("envmap: tracker back");
        tracker_ok = connected;
      }
    }
    const Nanos now = monotonic_now();
    if (now >= next_update) {
      write_now();
      next_update = now + update_every;
    }
    if (now >= next_progress && stitcher.frames_added() != reported) {
      reported = stitcher.frames_added();
      spdlog::info("envmap: {} frames stitched, {:.1f} % covered", stitcher.frames_added(), covered_percent(stitcher));
      next_progress = now + kNanosPerSecond;
    }
    capture::Frame frame;
    if (!queue.pop(frame, 50'000'000)) {
      if (queue.closed()) break;
      continue;
    }
    ++frames;
    std::optional<Pose> pose;
    const double exposure = exposures[std::size_t(std::max<std::int64_t>(0, frame.index)) % exposures.size()];
    if (replay) {
      const auto it = recorded_time.find(frame.index);
      if (it != recorded_time.end()) pose = replay->tracked_camera_pose(it->second);
    } else {
      // Hold the frame until the tracker has a sample past its time: interpolate, not extrapolate.
      const Nanos deadline = monotonic_now() + max_wait;
      for (;;) {
        samples.clear();
        driver->take_samples(samples);
        pairing.add(samples);
        if (pairing.covers(frame.time) || monotonic_now() >= deadline) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      const Nanos t = frame.time;
      const capture::PairedFrame paired = pairing.pair(std::move(frame));
      // An extrapolated pose is a guess; a map keeps what it was given, so skip it.
      if (paired.T_world_camera && paired.sensor.status != tracking::PoseStatus::Extrapolated)
        pose = paired.T_world_camera;
      if (frames % 300 == 0) pairing.forget_before(t - kNanosPerSecond);
      frame = paired.frame;
    }
    if (!pose) {
      ++without_pose;
      continue;
    }
    stitcher.add_frame(frame.image, pose->rotation, exposure);
    position_sum += pose->translation;
    if (o.refine_at_end && kept_all) {
      if (int(kept_frames.size()) >= o.keep_frames) {
        kept_all = false;
        kept_frames.clear();
        spdlog::warn("envmap: more than {} frames (--keep-frames): the sweep will not be refined at the end",
                     o.keep_frames);
        continue;
      }
      kept_frames.push_back(frame.image.clone());
      kept.rotations.push_back(pose->rotation);
      kept.exposures.push_back(exposure);
      kept.labels.push_back(std::to_string(frame.index) + "," + std::to_string(frame.time));
      if (bracket) kept.groups.push_back(int(frame.index / std::int64_t(exposures.size())));
      if (replay && !replay->reader().truth().empty()) {
        const auto truth = replay->true_camera_pose(frame.index);
        kept.truth.push_back(truth ? std::optional<glm::dquat>(truth->rotation) : std::nullopt);
      }
    }
  }
  capture.stop();
  if (driver) driver->stop();
  write_now();
  spdlog::info("envmap: {} frames, {} stitched, {} without a pose, {} updates of {}", frames, stitcher.frames_added(),
               without_pose, updates, o.out.out);
  if (stitcher.frames_added() > 0) compare_with_reference(stitcher.current_map(), stitcher.coverage(), reference);
  if (o.refine_at_end && kept_all && !kept_frames.empty()) {
    spdlog::info("envmap: the sweep is over; refining its {} frames and stitching them again", kept_frames.size());
    kept.stitch = st;
    kept.stitch.capture_position = position_sum / double(stitcher.frames_added());
    kept.read_frames = [&kept_frames](const std::function<void(const cv::Mat&, int)>& use) {
      for (int k = 0; k < int(kept_frames.size()); ++k) use(kept_frames[k], k);
    };
    EnvmapOutputOptions out = o.out;
    out.no_refine = false;
    out.reference = reference;
    stitch_sweep(kept, out);
  }
  if (capture.end() == capture::CaptureEnd::Vanished || capture.end() == capture::CaptureEnd::Failed) {
    if (capture.input_error()) throw InputError(capture.message());
    throw RuntimeError(capture.message());
  }
  if (stitcher.frames_added() == 0 && stop_requested()) {
    spdlog::warn("envmap: stopped before any frame was stitched; no map written");
    return;
  }
  if (stitcher.frames_added() == 0)
    throw RuntimeError("envmap: no frame was paired with a pose (" + std::to_string(frames) +
                       " frames); check the tracker (--tracker, --rig, --latency-ms) and start the sweep again");
}

}  // namespace lumar::pipeline
