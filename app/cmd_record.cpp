// lumar record: frames from any source (a camera, a video file, an image sequence, a
// recording) and the raw stream of a tracker, into a recording that a crash cannot
// tear (capture/recording_writer.h). A camera that vanishes or a disk that fills ends
// the recording early with one clear line, and what was written stays readable.
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/statvfs.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.h"
#include "lumar/base/error.h"
#include "lumar/capture/capture_thread.h"
#include "lumar/capture/recording_writer.h"
#include "lumar/pipeline/live_inputs.h"
#include "lumar/pipeline/stop_signal.h"

namespace lumar::app {

namespace {

struct RecordOptions {
  pipeline::LiveInputOptions in;
  std::string out;
  std::string codec = "mjpeg";
  int quality = 95;
  double segment_seconds = 1.0;
  double duration_s = 0;
  int max_frames = 0;
  double min_free_mb = 256;
};

// Free bytes for an unprivileged writer on the file system that holds `dir`.
double free_megabytes(const std::filesystem::path& dir) {
  struct statvfs st {};
  if (statvfs(dir.c_str(), &st) != 0) return 1e18;  // cannot tell: do not stop for it
  return double(st.f_bavail) * double(st.f_frsize) / (1024.0 * 1024.0);
}

void run_record(const RecordOptions& o) {
  if (o.in.source.empty())
    throw InputError("record: give --source (video:FILE, images:DIR, v4l2:/dev/videoN, recording:DIR)");
  if (!(o.segment_seconds > 0) || o.segment_seconds > 60) throw InputError("--segment-seconds must be in (0, 60]");
  if (!(o.duration_s >= 0)) throw InputError("--duration must be 0 or more");
  if (std::error_code ec; std::filesystem::exists(o.out, ec))
    throw InputError(o.out + ": already exists; choose a new recording directory");

  pipeline::LiveSource live = pipeline::open_live_source(o.in);
  const cv::Size size = live.source->frame_size();
  double fps = live.source->nominal_fps();
  if (!(fps > 0)) fps = 30;
  const CameraIntrinsics camera = pipeline::live_camera(o.in, size.width, size.height);

  capture::RecordingWriter* writer_ptr = nullptr;
  Nanos start = 0;
  std::atomic<std::uint64_t> raw_errors{0};
  auto driver = pipeline::make_tracker_driver(o.in, [&](const tracking::ByteChunk& chunk) {
    if (!writer_ptr) return;
    try {
      writer_ptr->add_tracker_bytes({chunk.arrival - start, chunk.bytes});
    } catch (...) {
      ++raw_errors;  // the writer remembers the failure; the main loop reports it
    }
  });

  capture::RecordingSettings video;
  video.codec = o.codec;
  video.quality = o.quality;
  video.fps = fps;
  video.size = size;
  video.frames_per_segment = std::max(1, int(std::lround(fps * o.segment_seconds)));
  capture::RecordingWriter writer(o.out, pipeline::live_session(o.in, camera, driver.get()), video);

  pipeline::catch_stop_signals();
  start = monotonic_now();
  writer_ptr = &writer;
  if (driver) driver->start();
  const std::size_t queue_frames = std::size_t(std::max(8.0, 2 * fps));  // 2 s of slack for a slow disk
  capture::FrameQueue queue(queue_frames, capture::QueuePolicy::KeepAll);
  capture::CaptureThread capture(std::move(live.source), queue);
  std::printf("recording %s%s into %s (%dx%d at %.3g fps, %d frames per segment); Ctrl-C to stop\n",
              capture.describe().c_str(), o.in.tracker.empty() ? "" : (" and tracker " + o.in.tracker).c_str(),
              o.out.c_str(), size.width, size.height, fps, video.frames_per_segment);
  std::fflush(stdout);

  std::vector<tracking::PoseSample> samples;
  std::uint64_t frames = 0, poses = 0;
  Nanos last_report = start;
  std::string stop_reason;  // why the recording ended early ("" = normally)
  bool write_failed = false, input_failed = false;
  auto drain_poses = [&] {
    if (!driver) return;
    samples.clear();
    driver->take_samples(samples);
    for (auto s : samples) {
      s.time -= start;
      writer.add_pose(s);
      ++poses;
    }
  };
  try {
    const Nanos end = o.duration_s > 0 ? start + seconds_to_nanos(o.duration_s) : 0;
    capture::Frame frame;
    while (!pipeline::stop_requested() && (end == 0 || monotonic_now() < end) &&
           (o.max_frames <= 0 || int(frames) < o.max_frames)) {
      if (queue.pop(frame, 50'000'000)) {
        frame.time -= start;
        writer.add_frame(frame);
        ++frames;
        // Before each new segment: stop cleanly while there is still room for it.
        if (frames % std::uint64_t(video.frames_per_segment) == 0 && free_megabytes(o.out) < o.min_free_mb) {
          stop_reason = o.out + ": the disk is nearly full (less than " + fmt::format("{:g}", o.min_free_mb) +
                        " MB free); recording stopped";
          break;
        }
      } else if (queue.closed()) {
        break;  // the source ended
      }
      drain_poses();
      if (raw_errors > 0) writer.add_tracker_bytes({});  // the tracker thread hit a write failure: this rethrows it
      const Nanos now = monotonic_now();
      if (now - last_report >= kNanosPerSecond) {
        const auto qs = queue.stats();
        std::printf("record: %llu frames written, %llu poses, %llu frames waiting, back-pressure %llu\n",
                    (unsigned long long)writer.frames_written(), (unsigned long long)poses,
                    (unsigned long long)queue.size(), (unsigned long long)qs.back_pressure);
        std::fflush(stdout);
        last_report = now;
      }
    }
  } catch (const InputError& e) {  // a frame the writer refuses: still close everything in order
    stop_reason = e.what();
    input_failed = true;
  } catch (const std::exception& e) {
    stop_reason = e.what();
    write_failed = true;
  }
  capture.stop();
  if (driver) driver->stop();
  if (!write_failed && !input_failed) {
    try {
      // Frames still queued were captured: they belong in the recording.
      capture::Frame frame;
      while (queue.pop(frame, 0)) {
        frame.time -= start;
        writer.add_frame(frame);
        ++frames;
      }
      drain_poses();
    } catch (const std::exception& e) {
      stop_reason = e.what();
      write_failed = true;
    }
  }
  if (stop_reason.empty() &&
      (capture.end() == capture::CaptureEnd::Vanished || capture.end() == capture::CaptureEnd::Failed))
    stop_reason = capture.message();
  try {
    writer.close();
  } catch (const std::exception& e) {
    if (stop_reason.empty()) stop_reason = e.what();
  }
  const auto qs = queue.stats();
  spdlog::info(
      "record: {} frames in {} ({} read from the source), {} poses; back-pressure {} times, {:.1f} ms in total",
      writer.frames_written(), o.out, capture.frames_read(), poses, qs.back_pressure,
      double(qs.back_pressure_time) * 1e-6);
  if (driver) {
    const auto st = driver->status();
    spdlog::info("record: tracker {} records, {} rejected, {} skipped bytes", st.records, st.rejected_records,
                 st.skipped_bytes);
  }
  if (!stop_reason.empty()) {
    const std::string kept =
        "; " + o.out + " holds the " + std::to_string(writer.frames_written()) + " frames written before it";
    if (input_failed || (capture.end() == capture::CaptureEnd::Failed && capture.input_error() && !write_failed))
      throw InputError(stop_reason + kept);
    throw RuntimeError(stop_reason + kept);
  }
}

}  // namespace

void register_record(CLI::App& app) {
  auto o = std::make_shared<RecordOptions>();
  auto* cmd = app.add_subcommand("record", "Record frames from a source and a tracker's raw stream into a recording");
  cmd->add_option("--source", o->in.source, "video:FILE, images:DIR_OR_GLOB, v4l2:/dev/videoN or recording:DIR")
      ->required();
  cmd->add_option("--out", o->out, "Recording directory to create (must not exist)")->required();
  add_live_input_options(cmd, o->in);
  cmd->add_option("--codec", o->codec, "Video codec: mjpeg (near-lossless) or ffv1 (lossless)")
      ->check(CLI::IsMember({"mjpeg", "ffv1"}))
      ->capture_default_str();
  cmd->add_option("--quality", o->quality, "MJPEG quality")->check(CLI::Range(50, 100))->capture_default_str();
  cmd->add_option("--segment-seconds", o->segment_seconds,
                  "Video segment length: at most this much video is lost in a crash")
      ->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "Stop after this many seconds (0: at the end of the source or Ctrl-C)")
      ->capture_default_str();
  cmd->add_option("--max-frames", o->max_frames, "Stop after this many frames (0: no limit)")->capture_default_str();
  cmd->add_option("--min-free-mb", o->min_free_mb, "Stop cleanly when the disk has less free space than this")
      ->capture_default_str();
  add_action(cmd, [o] { run_record(*o); });
}

}  // namespace lumar::app
