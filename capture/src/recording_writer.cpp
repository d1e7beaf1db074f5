#include "lumar/capture/recording_writer.h"

#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <exception>
#include <mutex>
#include <opencv2/videoio.hpp>
#include <thread>
#include <vector>

#include "lumar/base/csv.h"
#include "lumar/base/error.h"
#include "lumar/base/output_file.h"
#include "lumar/capture/append_file.h"
#include "lumar/capture/tracker_raw.h"

namespace lumar::capture {
namespace fs = std::filesystem;

namespace {

// Logs are flushed and fdatasync'd this often, so that at most ~100 ms of tracker
// data is lost in a crash (period plus the time one sync takes).
constexpr auto kFlushPeriod = std::chrono::milliseconds(50);

// An append-only log with its own lock, flushed by the background flusher.
struct SyncedLog {
  std::mutex mutex;
  AppendFile file;
  bool dirty = false;
};

void append_pose_fields(std::string& out, const Pose& p) {
  for (double v :
       {p.translation.x, p.translation.y, p.translation.z, p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z}) {
    out.push_back(',');
    csv::append_double(out, v);
  }
}

// OpenCV's video writer does not report failed writes (a full disk, a file size
// limit): it leaves a short file. Its AVI header, patched at release() near the start
// of the file, still gives the size the file should have; a shorter file is torn.
void check_avi_complete(const fs::path& file, std::uintmax_t size) {
  std::FILE* f = std::fopen(file.c_str(), "rb");
  unsigned char h[8] = {};
  const bool read = f && std::fread(h, 1, 8, f) == 8;
  if (f) std::fclose(f);
  const std::uint64_t riff =
      std::uint64_t(h[4]) | std::uint64_t(h[5]) << 8 | std::uint64_t(h[6]) << 16 | std::uint64_t(h[7]) << 24;
  if (!read || std::memcmp(h, "RIFF", 4) != 0 || riff == 0 || riff + 8 > size)
    throw RuntimeError(file.string() + ": the video segment was cut short (" + std::to_string(size) +
                       " bytes written); the disk is full or a file size limit was hit");
}

// The directory that holds `dir`'s entry, for fsync after creating `dir`.
fs::path parent_of(const fs::path& dir) {
  fs::path p = fs::absolute(dir).lexically_normal();
  if (!p.has_filename()) p = p.parent_path();  // "rec/" -> "rec"
  return p.parent_path();
}

}  // namespace

struct RecordingWriter::Impl {
  fs::path dir;
  nlohmann::json session;
  RecordingSettings settings;

  std::mutex video_mutex;
  cv::VideoWriter segment;
  bool segment_open = false;
  int segment_number = 0;
  std::vector<FrameEntry> segment_rows;
  AppendFile frames_csv;
  std::atomic<std::int64_t> frames_written{0};
  std::int64_t frames_added = 0, last_index = 0;  // under video_mutex
  Nanos last_time = 0;

  SyncedLog tracker, poses, truth;

  std::mutex state_mutex;  // guards stopping and first_error
  std::condition_variable flusher_wake;
  bool stopping = false;
  std::exception_ptr first_error;
  std::atomic<bool> failed{false};
  std::thread flusher;

  std::mutex close_mutex;
  std::atomic<bool> closed{false};

  std::string what() const { return "recording " + dir.string(); }

  void record_failure(std::exception_ptr e) {
    std::lock_guard lock(state_mutex);
    if (!first_error) first_error = e;
    failed = true;
  }
  std::atomic<bool> error_told{false};  // a caller was thrown the failure

  // Throws when closed, or when an earlier write failed (the data would be lost).
  void check_usable() {
    if (closed) throw RuntimeError(what() + ": already closed; data added after close() is lost");
    if (failed) {
      std::lock_guard lock(state_mutex);
      error_told = true;
      std::rethrow_exception(first_error);
    }
  }

  void flush_logs() {
    std::vector<SyncedLog*> to_sync;
    {
      // All three at once: flushed one by one, a pose appended between the tracker's
      // flush and the poses' flush could reach the disk before its raw bytes.
      std::scoped_lock lock(tracker.mutex, poses.mutex, truth.mutex);
      for (SyncedLog* log : {&tracker, &poses, &truth}) {
        if (!log->dirty) continue;
        log->file.flush();
        log->dirty = false;
        to_sync.push_back(log);
      }
    }
    // Outside the locks: a slow disk must not stall the tracker thread's appends.
    for (SyncedLog* log : to_sync) log->file.datasync();
  }

  void flush_loop() {
    std::unique_lock lock(state_mutex);
    while (!flusher_wake.wait_for(lock, kFlushPeriod, [this] { return stopping; })) {
      lock.unlock();
      try {
        flush_logs();
      } catch (...) {
        record_failure(std::current_exception());
        return;
      }
      lock.lock();
    }
  }

  void write_session() { write_file_atomically(dir / kSessionFile, session.dump(2) + "\n"); }

  void open_segment() {
    const fs::path path = partial_segment_path(dir, settings.codec, segment_number);
    bool ok = false;
    if (settings.codec == "mjpeg") {
      ok = segment.open(path.string(), cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), settings.fps,
                        settings.size);
      // OpenCV 4.6's MJPEG writer ignores a quality given to open(); set() works.
      // Its encoder also drops the last 4 bytes of about 1 frame in 32 (opencv#24171,
      // fixed in 4.9): that frame's bottom-right 16x16 block decodes 2-3 levels off
      // and libjpeg warns "premature end of data segment". Use ffv1 where that matters.
      if (ok && !segment.set(cv::VIDEOWRITER_PROP_QUALITY, settings.quality))
        throw RuntimeError(path.string() + ": OpenCV's MJPEG writer refused quality " +
                           std::to_string(settings.quality));
    } else {
      ok = segment.open(path.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), settings.fps,
                        settings.size);
    }
    if (!ok)
      throw RuntimeError(path.string() + ": OpenCV cannot open a " + settings.codec +
                         " video writer; check the disk and that OpenCV has " +
                         (settings.codec == "mjpeg" ? "its MJPEG backend" : "FFmpeg with FFV1"));
    segment_open = true;
  }

  // Order matters for crash safety: the segment is complete on disk under its final
  // name before frames.csv names it.
  void close_segment() {
    segment.release();
    segment_open = false;
    const fs::path partial = partial_segment_path(dir, settings.codec, segment_number);
    const fs::path final_path = segment_path(dir, settings.codec, segment_number);
    std::error_code ec;
    const auto size = fs::file_size(partial, ec);
    if (size == 0 || ec) throw RuntimeError(partial.string() + ": the video writer left no data; check free space");
    if (settings.codec == "mjpeg") check_avi_complete(partial, size);
    fsync_path(partial);
    fs::rename(partial, final_path, ec);
    if (ec) throw RuntimeError(final_path.string() + ": cannot rename the closed segment (" + ec.message() + ")");
    fsync_path(dir / kVideoDir);

    std::string rows;
    for (const FrameEntry& r : segment_rows) {
      csv::append_int(rows, r.index);
      rows.push_back(',');
      csv::append_int(rows, r.time);
      rows.push_back(',');
      csv::append_int(rows, r.segment);
      rows.push_back(',');
      csv::append_int(rows, r.segment_frame);
      rows.push_back('\n');
    }
    frames_csv.append(rows);
    frames_csv.sync();
    frames_written += std::int64_t(segment_rows.size());
    segment_rows.clear();
    ++segment_number;
  }

  // Runs `fn` and turns any failure into the recording's first error.
  template <class F>
  void guarded(F&& fn) {
    try {
      fn();
    } catch (const InputError&) {
      throw;  // the caller's mistake; the recording is still fine
    } catch (...) {
      record_failure(std::current_exception());
      error_told = true;
      throw;
    }
  }

  void append_to(SyncedLog& log, const std::string& bytes) {
    std::lock_guard lock(log.mutex);
    if (closed) throw RuntimeError(what() + ": already closed; data added after close() is lost");
    log.file.append(bytes);
    log.dirty = true;
  }
};

RecordingWriter::RecordingWriter(const fs::path& dir, nlohmann::json session, RecordingSettings settings)
    : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.dir = dir;
  w.settings = std::move(settings);
  validate_recording_settings(w.settings, dir.string() + ": recording settings");
  if (session.is_null()) session = nlohmann::json::object();
  if (!session.is_object())
    throw InputError(dir.string() + ": session metadata must be a JSON object, not " +
                     std::string(session.type_name()));

  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec))
      throw InputError(dir.string() + ": exists and is not a directory; choose a new recording directory");
    if (!fs::is_empty(dir, ec))
      throw InputError(dir.string() + ": directory is not empty; choose a new recording directory");
  }
  fs::create_directories(dir / kVideoDir, ec);
  if (ec)
    throw InputError(dir.string() + ": cannot create the recording directory (" + ec.message() +
                     "); check the path and permissions");

  // Data files first, session.json last: a directory with a session.json always
  // has all of its files.
  w.frames_csv = AppendFile(dir / kFramesFile);
  w.frames_csv.append(std::string(kFramesHeader) + "\n");
  w.frames_csv.sync();
  w.tracker.file = AppendFile(dir / kTrackerFile);
  w.tracker.file.sync();
  w.poses.file = AppendFile(dir / kPosesFile);
  w.poses.file.append(std::string(kPosesHeader) + "\n");
  w.poses.file.sync();
  fsync_path(dir / kVideoDir);

  session["format"] = kRecordingFormat;
  session["version"] = kRecordingVersion;
  session["complete"] = false;
  session.erase("frames");
  nlohmann::json video = {{"codec", w.settings.codec},
                          {"frames_per_segment", w.settings.frames_per_segment},
                          {"fps", w.settings.fps},
                          {"width", w.settings.size.width},
                          {"height", w.settings.size.height}};
  if (w.settings.codec == "mjpeg") video["quality"] = w.settings.quality;
  session["video"] = std::move(video);
  w.session = std::move(session);
  w.write_session();  // also syncs `dir`
  fsync_path(parent_of(dir));

  w.flusher = std::thread([&w] { w.flush_loop(); });
}

RecordingWriter::~RecordingWriter() {
  if (!impl_) return;
  // A failure a caller was already thrown (a full disk in add_frame) is not said twice.
  const bool already_failed = impl_->error_told;
  try {
    close();
  } catch (const std::exception& e) {
    if (!already_failed) spdlog::error("{}", e.what());
  } catch (...) {
    if (!already_failed) spdlog::error("{}: closing failed", impl_->what());
  }
  if (impl_->flusher.joinable()) impl_->flusher.join();
}

void RecordingWriter::add_frame(const Frame& frame) {
  Impl& w = *impl_;
  w.check_usable();
  const cv::Mat& img = frame.image;
  if (img.empty() || img.type() != CV_8UC3 || img.size() != w.settings.size)
    throw InputError(w.what() + ": frame " + std::to_string(frame.index) + " is " + std::to_string(img.cols) + "x" +
                     std::to_string(img.rows) + " with " + std::to_string(img.channels()) +
                     " channels; the recording takes 8-bit BGR " + std::to_string(w.settings.size.width) + "x" +
                     std::to_string(w.settings.size.height));
  std::lock_guard lock(w.video_mutex);
  if (w.closed) throw RuntimeError(w.what() + ": already closed; frames added after close() are lost");
  // The reader holds frames.csv to this (a file out of order is a damaged one).
  if (frame.index < 0 || frame.time < 0)
    throw InputError(w.what() + ": frame " + std::to_string(frame.index) + " at " + std::to_string(frame.time) +
                     " ns: indices and times count from 0");
  if (w.frames_added > 0 && (frame.index <= w.last_index || frame.time <= w.last_time))
    throw InputError(w.what() + ": frame " + std::to_string(frame.index) + " at " + std::to_string(frame.time) +
                     " ns comes after frame " + std::to_string(w.last_index) + " at " + std::to_string(w.last_time) +
                     " ns; a source's frame numbers and times must increase");
  w.last_index = frame.index;
  w.last_time = frame.time;
  ++w.frames_added;
  w.guarded([&] {
    if (!w.segment_open) w.open_segment();
    w.segment.write(img);
    w.segment_rows.push_back({frame.index, frame.time, w.segment_number, int(w.segment_rows.size())});
    if (int(w.segment_rows.size()) == w.settings.frames_per_segment) w.close_segment();
  });
}

void RecordingWriter::add_tracker_bytes(const tracking::ByteChunk& chunk) {
  Impl& w = *impl_;
  w.check_usable();
  std::string bytes;
  append_tracker_chunk(bytes, chunk);
  w.guarded([&] { w.append_to(w.tracker, bytes); });
}

void RecordingWriter::add_pose(const tracking::PoseSample& sample) {
  Impl& w = *impl_;
  w.check_usable();
  if (!sample.T_transmitter_sensor.is_finite())
    throw InputError(w.what() + ": pose sample at " + std::to_string(sample.time) +
                     " ns holds a non-finite number; fix the tracker decoding");
  std::string row;
  csv::append_int(row, sample.time);
  row.push_back(',');
  csv::append_int(row, sample.station);
  append_pose_fields(row, sample.T_transmitter_sensor);
  row.push_back('\n');
  w.guarded([&] { w.append_to(w.poses, row); });
}

void RecordingWriter::add_truth(std::int64_t index, Nanos time, const Pose& T_world_camera) {
  Impl& w = *impl_;
  w.check_usable();
  if (!T_world_camera.is_finite())
    throw InputError(w.what() + ": true pose of frame " + std::to_string(index) + " holds a non-finite number");
  std::string row;
  csv::append_int(row, index);
  row.push_back(',');
  csv::append_int(row, time);
  append_pose_fields(row, T_world_camera);
  row.push_back('\n');
  w.guarded([&] {
    {
      // truth.csv exists only in recordings that have truth: create it on first use.
      std::lock_guard lock(w.truth.mutex);
      if (!w.truth.file.is_open() && !w.closed) {
        w.truth.file = AppendFile(w.dir / kTruthFile);
        w.truth.file.append(std::string(kTruthHeader) + "\n");
        w.truth.file.sync();
        fsync_path(w.dir);
      }
    }
    w.append_to(w.truth, row);
  });
}

void RecordingWriter::close() {
  Impl& w = *impl_;
  std::lock_guard close_lock(w.close_mutex);
  if (w.closed.exchange(true)) return;
  {
    std::lock_guard lock(w.state_mutex);
    w.stopping = true;
  }
  w.flusher_wake.notify_all();
  if (w.flusher.joinable()) w.flusher.join();

  // Save as much as possible even after a failure, then report the first one.
  auto attempt = [&w](auto&& fn) {
    try {
      fn();
    } catch (...) {
      w.record_failure(std::current_exception());
    }
  };
  attempt([&] {
    std::lock_guard lock(w.video_mutex);
    if (w.segment_open) w.close_segment();
  });
  for (SyncedLog* log : {&w.tracker, &w.poses, &w.truth})
    attempt([&] {
      std::lock_guard lock(log->mutex);
      log->file.close();
    });
  attempt([&] { w.frames_csv.close(); });
  if (w.failed) {
    std::lock_guard lock(w.state_mutex);
    std::rethrow_exception(w.first_error);  // session.json keeps "complete": false
  }
  w.session["complete"] = true;
  w.session["frames"] = w.frames_written.load();
  w.write_session();
}

std::int64_t RecordingWriter::frames_written() const { return impl_->frames_written; }

const fs::path& RecordingWriter::directory() const { return impl_->dir; }

}  // namespace lumar::capture
