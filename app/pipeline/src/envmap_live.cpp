#include "lumar/pipeline/envmap_live.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <optional>

#include "lumar/base/error.h"
#include "lumar/calib/camera_response.h"
#include "lumar/capture/recording_replay.h"
#include "lumar/pipeline/live_loop.h"

namespace lumar::pipeline {

namespace {

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
  const auto replay = recorded_poses_of(o.in);
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
  std::string reference = o.out.reference;  // a synthetic recording's source map by default
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
    st.response = calib::calibrated_response(session.radiometry, replay->reader().directory())
                      .value_or(calib::srgb_response(1.0));
    st.vignetting_a = session.radiometry.vignetting_a;
    st.vignetting_b = session.radiometry.vignetting_b;
    exposures =
        session.frame_exposures.empty() ? std::vector<double>{session.radiometry.exposure} : session.frame_exposures;
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

  LiveLoopSettings settings;
  settings.what = "envmap";
  // A camera cannot wait: keep the newest frames. A file can: stitch every frame.
  settings.policy = live.camera ? capture::QueuePolicy::KeepNewest : capture::QueuePolicy::KeepAll;
  settings.queue_frames = 4;
  settings.max_wait = seconds_to_nanos(o.max_wait_ms * 1e-3);
  settings.duration = o.duration_s > 0 ? seconds_to_nanos(o.duration_s) : 0;
  LiveLoop loop(std::move(live.source), make_tracker_driver(o.in, {}), live_rig(o.rig, o.in.latency_ms), settings);
  if (replay) loop.use_recorded_poses(replay);
  // A frame without a pose is lost to the map: start the camera once poses flow.
  loop.wait_for_tracker(seconds_to_nanos(o.tracker_timeout_s), o.in.tracker);
  if (!replay && o.in.camera_file.empty())
    spdlog::warn("envmap: no --camera; assuming a pinhole with focal length {} px and no distortion", size.width);

  const Nanos update_every = seconds_to_nanos(o.update_every_s);
  Nanos next_update = monotonic_now() + update_every, next_progress = monotonic_now() + kNanosPerSecond;
  std::uint64_t skipped = 0, updates = 0;
  glm::dvec3 position_sum(0.0);
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

  loop.run(
      [&](capture::PairedFrame& paired) {
        // An extrapolated pose is a guess; a map keeps what it was given, so skip it.
        if (!paired.T_world_camera || paired.sensor.status == tracking::PoseStatus::Extrapolated) {
          ++skipped;
          return true;
        }
        const capture::Frame& frame = paired.frame;
        const Pose& pose = *paired.T_world_camera;
        const double exposure = exposures[std::size_t(std::max<std::int64_t>(0, frame.index)) % exposures.size()];
        stitcher.add_frame(frame.image, pose.rotation, exposure);
        position_sum += pose.translation;
        if (!o.refine_at_end || !kept_all) return true;
        if (int(kept_frames.size()) >= o.keep_frames) {
          kept_all = false;
          kept_frames.clear();
          spdlog::warn("envmap: more than {} frames (--keep-frames): the sweep will not be refined at the end",
                       o.keep_frames);
          return true;
        }
        kept_frames.push_back(frame.image.clone());
        kept.rotations.push_back(pose.rotation);
        kept.exposures.push_back(exposure);
        kept.labels.push_back(std::to_string(frame.index) + "," + std::to_string(frame.time));
        if (bracket) kept.groups.push_back(int(frame.index / std::int64_t(exposures.size())));
        if (replay && !replay->reader().truth().empty()) {
          const auto truth = replay->true_camera_pose(frame.index);
          kept.truth.push_back(truth ? std::optional<glm::dquat>(truth->rotation) : std::nullopt);
        }
        return true;
      },
      [&] {
        const Nanos now = monotonic_now();
        if (now >= next_update) {
          write_now();
          next_update = now + update_every;
        }
        if (now >= next_progress && stitcher.frames_added() != reported) {
          reported = stitcher.frames_added();
          spdlog::info("envmap: {} frames stitched, {:.1f} % covered", stitcher.frames_added(),
                       covered_percent(stitcher));
          next_progress = now + kNanosPerSecond;
        }
        return true;
      });
  write_now();
  spdlog::info("envmap: {} frames, {} stitched, {} without a pose, {} updates of {}", loop.stats().frames,
               stitcher.frames_added(), skipped, updates, o.out.out);
  if (stitcher.frames_added() > 0) {
    const EnvironmentMap map = stitcher.current_map();
    warn_about_exposure_range(stitcher, map, exposures);
    compare_with_reference(map, stitcher.coverage(), reference);
  }
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
  loop.check_source();
  if (stitcher.frames_added() == 0 && loop.stopped_by_signal()) {
    spdlog::warn("envmap: stopped before any frame was stitched; no map written");
    return;
  }
  if (stitcher.frames_added() == 0)
    throw RuntimeError("envmap: no frame was paired with a pose (" + std::to_string(loop.stats().frames) +
                       " frames); check the tracker (--tracker, --rig, --latency-ms) and start the sweep again");
}

}  // namespace lumar::pipeline
