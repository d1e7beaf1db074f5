#include "lumar/pipeline/live_record.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/statvfs.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "lumar/base/error.h"
#include "lumar/capture/recording_writer.h"
#include "lumar/pipeline/live_loop.h"

namespace lumar::pipeline {

namespace {

// Free bytes for an unprivileged writer on the file system that holds `dir`.
double free_megabytes(const std::filesystem::path& dir) {
  struct statvfs st {};
  if (statvfs(dir.c_str(), &st) != 0) return 1e18;  // cannot tell: do not stop for it
  return double(st.f_bavail) * double(st.f_frsize) / (1024.0 * 1024.0);
}

}  // namespace

void record_live(const RecordOptions& o) {
  if (o.in.source.empty())
    throw InputError("record: give --source (video:FILE, images:DIR, v4l2:/dev/videoN, recording:DIR)");
  if (!(o.segment_seconds > 0) || o.segment_seconds > 60) throw InputError("--segment-seconds must be in (0, 60]");
  if (!(o.duration_s >= 0)) throw InputError("--duration must be 0 or more");
  if (std::error_code ec; std::filesystem::exists(o.out, ec))
    throw InputError(o.out + ": already exists; choose a new recording directory");

  LiveSource live = open_live_source(o.in);
  const cv::Size size = live.source->frame_size();
  const double shutter_s = source_shutter_s(*live.source);
  double fps = live.source->nominal_fps();
  if (!(fps > 0)) fps = 30;
  const CameraIntrinsics camera = live_camera(o.in, size.width, size.height);

  capture::RecordingWriter* writer_ptr = nullptr;
  Nanos start = 0;
  std::atomic<std::uint64_t> raw_errors{0};
  auto driver = make_tracker_driver(o.in, [&](const tracking::ByteChunk& chunk) {
    if (!writer_ptr) return;
    try {
      writer_ptr->add_tracker_bytes({chunk.arrival - start, chunk.bytes});
    } catch (...) {
      ++raw_errors;  // the writer remembers the failure; the loop reports it
    }
  });

  capture::RecordingSettings video;
  video.codec = o.codec;
  video.quality = o.quality;
  video.fps = fps;
  video.size = size;
  video.frames_per_segment = std::max(1, int(std::lround(fps * o.segment_seconds)));
  capture::RecordingWriter writer(o.out, live_session(o.in, camera, driver.get(), shutter_s), video);

  LiveLoopSettings settings;
  settings.what = "record";
  settings.policy = capture::QueuePolicy::KeepAll;              // never drop a frame; wait for the disk
  settings.queue_frames = std::size_t(std::max(8.0, 2 * fps));  // 2 s of slack for a slow disk
  settings.max_wait = 0;  // a recording keeps the raw stream; pairing is for display
  settings.max_frames = o.max_frames;
  settings.duration = o.duration_s > 0 ? seconds_to_nanos(o.duration_s) : 0;
  settings.drain_on_stop = true;  // frames already captured belong in the recording
  LiveLoop loop(std::move(live.source), std::move(driver), tracking::Rig{}, settings);
  std::uint64_t poses = 0, frames_added = 0;
  loop.on_samples([&](const std::vector<tracking::PoseSample>& samples) {
    for (auto s : samples) {
      s.time -= start;
      writer.add_pose(s);
      ++poses;
    }
  });

  start = monotonic_now();
  writer_ptr = &writer;
  std::printf("recording %s%s into %s (%dx%d at %.3g fps, %d frames per segment); Ctrl-C to stop\n",
              loop.describe_source().c_str(), o.in.tracker.empty() ? "" : (" and tracker " + o.in.tracker).c_str(),
              o.out.c_str(), size.width, size.height, fps, video.frames_per_segment);
  std::fflush(stdout);

  std::string stop_reason;  // why the recording ended early ("" = normally)
  bool write_failed = false, input_failed = false;
  Nanos last_report = start;
  try {
    loop.run(
        [&](capture::PairedFrame& paired) {
          capture::Frame& frame = paired.frame;
          frame.time -= start;
          writer.add_frame(frame);
          // Before each new segment: stop cleanly while there is still room for it.
          if (++frames_added % std::uint64_t(video.frames_per_segment) == 0 && free_megabytes(o.out) < o.min_free_mb) {
            stop_reason = o.out + ": the disk is nearly full (less than " + fmt::format("{:g}", o.min_free_mb) +
                          " MB free); recording stopped";
            return false;
          }
          return true;
        },
        [&] {
          if (raw_errors > 0) writer.add_tracker_bytes({});  // the tracker thread hit a write failure: rethrows it
          const Nanos now = monotonic_now();
          if (now - last_report >= kNanosPerSecond) {
            std::printf("record: %llu frames written, %llu poses, %llu frames waiting, back-pressure %llu\n",
                        (unsigned long long)writer.frames_written(), (unsigned long long)poses,
                        (unsigned long long)loop.frames_waiting(),
                        (unsigned long long)loop.queue_stats().back_pressure);
            std::fflush(stdout);
            last_report = now;
          }
          return true;
        });
  } catch (const InputError& e) {  // a frame the writer refuses: still close everything in order
    stop_reason = e.what();
    input_failed = true;
  } catch (const std::exception& e) {
    stop_reason = e.what();
    write_failed = true;
  }
  const auto end = loop.source_end();
  if (stop_reason.empty() && (end == capture::CaptureEnd::Vanished || end == capture::CaptureEnd::Failed))
    stop_reason = loop.source_message();
  try {
    writer.close();
  } catch (const std::exception& e) {
    if (stop_reason.empty()) stop_reason = e.what();
  }
  const auto& qs = loop.stats().queue;
  spdlog::info(
      "record: {} frames in {} ({} read from the source), {} poses; back-pressure {} times, {:.1f} ms in total",
      writer.frames_written(), o.out, loop.frames_read(), poses, qs.back_pressure,
      double(qs.back_pressure_time) * 1e-6);
  if (const auto* d = loop.driver()) {
    const auto st = d->status();
    spdlog::info("record: tracker {} records, {} rejected, {} skipped bytes", st.records, st.rejected_records,
                 st.skipped_bytes);
  }
  if (!stop_reason.empty()) {
    const std::string kept =
        "; " + o.out + " holds the " + std::to_string(writer.frames_written()) + " frames written before it";
    if (input_failed || (end == capture::CaptureEnd::Failed && loop.source_input_error() && !write_failed))
      throw InputError(stop_reason + kept);
    throw RuntimeError(stop_reason + kept);
  }
}

}  // namespace lumar::pipeline
