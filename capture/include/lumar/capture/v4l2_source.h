#pragma once
// A V4L2 camera as a FrameSource: capability query, format negotiation (YUYV, MJPEG,
// or the BGR/RGB libv4l2 converts to), mmap streaming with at least four buffers,
// poll with timeouts, kernel timestamps, dropped frames from the buffer sequence
// numbers, exposure/gain controls, and a clean end when the camera is unplugged.
//
// Times: a buffer flagged V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC carries CLOCK_MONOTONIC
// of the start of exposure (TSTAMP_SRC_SOE) or of the end of the frame (EOF, what UVC
// cameras give). Frame::time is moved to the middle of the exposure when the exposure
// time is known (exposure_absolute); otherwise it is the kernel's time as is. A buffer
// without a monotonic timestamp is stamped at dequeue (stats().dequeue_stamped).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lumar/base/error.h"
#include "lumar/base/time.h"
#include "lumar/capture/frame_source.h"
#include "lumar/capture/v4l2_device.h"

namespace lumar::capture {

// The camera went away mid-stream (unplugged: ENODEV, or POLLERR/POLLHUP).
struct CameraVanished : RuntimeError {
  using RuntimeError::RuntimeError;
};

struct V4l2Settings {
  std::string path = "/dev/video0";
  int width = 640, height = 480;  // asked for; the driver picks the nearest it has
  double fps = 30;                // asked for with VIDIOC_S_PARM where supported (0: leave)
  // Pixel formats in order of preference, as fourcc strings.
  std::vector<std::string> formats{"YUYV", "MJPG", "BGR3", "RGB3"};
  int buffers = 4;                      // mmap buffers requested (at least 4)
  Nanos poll_timeout = 100'000'000;     // one poll(2) wait
  Nanos frame_timeout = 2'000'000'000;  // no frame this long: RuntimeError (never hang)
  // Radiometry: lock auto-exposure (manual mode) where the camera offers it, and set
  // exposure (100 us units, V4L2_CID_EXPOSURE_ABSOLUTE) and gain when >= 0.
  bool lock_exposure = true;
  int exposure_100us = -1;
  int gain = -1;
};

// Throws InputError naming the setting when it is unusable.
void validate_v4l2_settings(const V4l2Settings& settings);

struct V4l2Stats {
  std::uint64_t frames = 0;           // delivered by read()
  std::uint64_t dropped = 0;          // missing from the buffer sequence numbers
  std::uint64_t corrupt = 0;          // buffers flagged V4L2_BUF_FLAG_ERROR or undecodable
  std::uint64_t poll_timeouts = 0;    // poll(2) waits that ended with no frame (slow frames)
  std::uint64_t eagain = 0;           // VIDIOC_DQBUF said EAGAIN after poll said readable
  std::uint64_t dequeue_stamped = 0;  // frames stamped at dequeue (no monotonic timestamp)
};

// What was negotiated with the camera.
struct V4l2Format {
  std::string fourcc;  // "YUYV"
  int width = 0, height = 0;
  int bytes_per_line = 0;
  double fps = 0;                         // from VIDIOC_G_PARM (0 if the driver does not say)
  int buffers = 0;                        // mmap buffers granted
  bool emulated = false;                  // libv4l2 converts to this format in user space
  std::vector<std::string> offered;       // every format the device listed
  std::vector<std::string> controls_set;  // "auto_exposure=manual", "exposure_absolute=100", ...
};

class V4l2Source final : public FrameSource {
 public:
  // Opens, negotiates and starts streaming. InputError for a path that is not a video
  // capture device or offers none of the formats; RuntimeError when a step fails.
  V4l2Source(V4l2Settings settings, std::unique_ptr<V4l2Device> device = libv4l2_device());
  ~V4l2Source() override;  // stops streaming, unmaps, closes; never throws
  V4l2Source(const V4l2Source&) = delete;
  V4l2Source& operator=(const V4l2Source&) = delete;

  // The next frame, converted to BGR8. Waits at most settings.frame_timeout (in
  // poll_timeout steps): then RuntimeError. CameraVanished when the camera is unplugged.
  // Frame::index is the buffer sequence number since streaming began (gaps = drops).
  bool read(Frame& frame) override;
  cv::Size frame_size() const override { return {format_.width, format_.height}; }
  double nominal_fps() const override { return format_.fps > 0 ? format_.fps : settings_.fps; }
  std::string describe() const override { return "V4L2 camera " + settings_.path; }
  Nanos shutter_time() const override { return exposure_; }  // exposure_absolute (0: not known)

  const V4l2Format& format() const { return format_; }
  const V4l2Stats& stats() const { return stats_; }

 private:
  struct Buffer {
    void* start = nullptr;
    std::size_t length = 0;
  };
  void fail_errno(const std::string& step);
  void negotiate_format();
  void set_controls();
  void start_streaming();
  void stop_streaming() noexcept;
  // The frame's image, and its chroma sampling: YUYV's 2×1, an MJPEG frame's own header's.
  bool convert(const Buffer& buffer, std::size_t bytes_used, cv::Mat& bgr, ChromaSampling& chroma);
  [[noreturn]] void vanished();

  V4l2Settings settings_;
  std::unique_ptr<V4l2Device> device_;
  int fd_ = -1;
  std::uint32_t pixel_format_ = 0;
  std::vector<Buffer> buffers_;
  bool streaming_ = false;
  V4l2Format format_;
  V4l2Stats stats_;
  Nanos exposure_ = 0;             // known exposure time (0: unknown)
  std::int64_t index_offset_ = 0;  // Frame::index = sequence + index_offset_
  std::int64_t last_sequence_ = -1;
  Nanos last_time_ = 0;
};

}  // namespace lumar::capture
