#include "lumar/capture/v4l2_source.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>

#include "lumar/capture/jpeg_decoder.h"

namespace lumar::capture {

namespace {

std::string fourcc_text(std::uint32_t f) {
  std::string s;
  for (int i = 0; i < 4; ++i) s.push_back(char((f >> (8 * i)) & 0xFF));
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

std::uint32_t fourcc_code(const std::string& s) {
  std::string t = s;
  t.resize(4, ' ');
  return v4l2_fourcc(t[0], t[1], t[2], t[3]);
}

Nanos timeval_nanos(const timeval& tv) { return Nanos(tv.tv_sec) * kNanosPerSecond + Nanos(tv.tv_usec) * 1000; }

// A stream of undecodable frames is a fault, not something to wait out.
constexpr int kMaxCorruptRun = 30;

bool is_vanish_errno(int e) { return e == ENODEV || e == ENXIO || e == EIO; }

}  // namespace

void validate_v4l2_settings(const V4l2Settings& s) {
  if (s.path.empty()) throw InputError("v4l2: no device path given; use e.g. v4l2:/dev/video0 (see lumar devices)");
  if (s.width <= 0 || s.height <= 0)
    throw InputError(s.path + ": frame size " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                     " must be positive");
  if (!(s.fps >= 0) || !std::isfinite(s.fps)) throw InputError(s.path + ": frame rate must be 0 (leave) or positive");
  if (s.formats.empty()) throw InputError(s.path + ": no pixel format to ask for; give e.g. YUYV or MJPG");
  for (const auto& f : s.formats)
    if (f.empty() || f.size() > 4) throw InputError(s.path + ": pixel format '" + f + "' is not a fourcc like YUYV");
  if (s.buffers < 4 || s.buffers > 32) throw InputError(s.path + ": use 4 to 32 capture buffers");
  if (s.poll_timeout <= 0 || s.frame_timeout < s.poll_timeout)
    throw InputError(s.path + ": the frame timeout must be at least one poll timeout, both positive");
}

V4l2Source::V4l2Source(V4l2Settings settings, std::unique_ptr<V4l2Device> device)
    : settings_(std::move(settings)), device_(std::move(device)) {
  validate_v4l2_settings(settings_);
  const std::string& path = settings_.path;
  fd_ = device_->open(path, O_RDWR | O_NONBLOCK);
  if (fd_ < 0) {
    const int e = errno;
    if (e == ENOENT || e == ENODEV || e == ENXIO)
      throw InputError(path + ": no such camera; plug it in or pick one from `lumar devices`");
    throw RuntimeError(path + ": cannot open the camera (" + std::strerror(e) +
                       "); check permissions (group video) and that no other program uses it");
  }
  try {
    v4l2_capability cap{};
    if (xioctl(*device_, fd_, VIDIOC_QUERYCAP, &cap) < 0) {
      if (errno == ENOTTY) throw InputError(path + ": is not a V4L2 device; pick a camera from `lumar devices`");
      fail_errno("VIDIOC_QUERYCAP");
    }
    const __u32 caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE))
      throw InputError(path + ": is not a video capture node (a metadata or output node?); try the next /dev/video");
    if (!(caps & V4L2_CAP_STREAMING))
      throw InputError(path + ": does not support streaming I/O (mmap), which Lumar needs");
    negotiate_format();
    set_controls();
    start_streaming();
  } catch (...) {
    stop_streaming();
    throw;
  }
}

V4l2Source::~V4l2Source() { stop_streaming(); }

void V4l2Source::fail_errno(const std::string& step) {
  const int e = errno;
  if (is_vanish_errno(e)) vanished();
  throw RuntimeError(settings_.path + ": " + step + " failed (" + std::strerror(e) + ")");
}

void V4l2Source::vanished() {
  throw CameraVanished(settings_.path + ": the camera disappeared (unplugged?) after " + std::to_string(stats_.frames) +
                       " frames; plug it back in and start again");
}

void V4l2Source::negotiate_format() {
  const std::string& path = settings_.path;
  std::vector<std::pair<std::uint32_t, bool>> offered;  // fourcc, emulated
  for (__u32 i = 0;; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(*device_, fd_, VIDIOC_ENUM_FMT, &d) < 0) {
      if (errno == EINVAL) break;  // end of the list
      fail_errno("VIDIOC_ENUM_FMT");
    }
    offered.emplace_back(d.pixelformat, (d.flags & V4L2_FMT_FLAG_EMULATED) != 0);
    format_.offered.push_back(fourcc_text(d.pixelformat));
  }
  // The first preferred format the device offers; native before libv4l2-emulated.
  bool found = false;
  for (int pass = 0; pass < 2 && !found; ++pass)
    for (const auto& want : settings_.formats) {
      const std::uint32_t code = fourcc_code(want);
      auto it = std::find_if(offered.begin(), offered.end(),
                             [&](const auto& o) { return o.first == code && o.second == (pass == 1); });
      if (it != offered.end()) {
        pixel_format_ = code;
        format_.emulated = it->second;
        found = true;
        break;
      }
    }
  if (!found) {
    std::string list;
    for (const auto& f : format_.offered) list += (list.empty() ? "" : " ") + f;
    throw InputError(path + ": offers none of the pixel formats Lumar decodes (offers: " +
                     (list.empty() ? "none" : list) + "); use a camera with YUYV or MJPEG");
  }

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = __u32(settings_.width);
  fmt.fmt.pix.height = __u32(settings_.height);
  fmt.fmt.pix.pixelformat = pixel_format_;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  if (xioctl(*device_, fd_, VIDIOC_S_FMT, &fmt) < 0) fail_errno("VIDIOC_S_FMT");
  if (fmt.fmt.pix.pixelformat != pixel_format_)
    throw RuntimeError(path + ": asked for " + fourcc_text(pixel_format_) + ", the driver chose " +
                       fourcc_text(fmt.fmt.pix.pixelformat) + "; pick that one with --format");
  format_.fourcc = fourcc_text(pixel_format_);
  format_.width = int(fmt.fmt.pix.width);
  format_.height = int(fmt.fmt.pix.height);
  format_.bytes_per_line = int(fmt.fmt.pix.bytesperline);
  if (format_.width <= 0 || format_.height <= 0) throw RuntimeError(path + ": the driver reports an empty frame size");
  if (format_.width != settings_.width || format_.height != settings_.height)
    spdlog::info("{}: asked for {}x{}, the camera gives {}x{}", path, settings_.width, settings_.height, format_.width,
                 format_.height);

  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(*device_, fd_, VIDIOC_G_PARM, &parm) == 0) {
    if (settings_.fps > 0 && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
      parm.parm.capture.timeperframe.numerator = 1000;
      parm.parm.capture.timeperframe.denominator = __u32(std::lround(settings_.fps * 1000));
      if (xioctl(*device_, fd_, VIDIOC_S_PARM, &parm) < 0) fail_errno("VIDIOC_S_PARM");
    }
    const auto& tpf = parm.parm.capture.timeperframe;
    if (tpf.numerator > 0 && tpf.denominator > 0) format_.fps = double(tpf.denominator) / tpf.numerator;
  }
}

void V4l2Source::set_controls() {
  // A control the camera lacks is fine (EINVAL); anything else is worth a warning only:
  // the picture still comes, just with auto exposure.
  auto set = [&](std::uint32_t id, int value, const char* name) {
    v4l2_queryctrl q{};
    q.id = id;
    if (xioctl(*device_, fd_, VIDIOC_QUERYCTRL, &q) < 0 || (q.flags & V4L2_CTRL_FLAG_DISABLED)) return false;
    v4l2_control c{};
    c.id = id;
    c.value = std::clamp(value, q.minimum, q.maximum);
    if (xioctl(*device_, fd_, VIDIOC_S_CTRL, &c) < 0) {
      if (is_vanish_errno(errno)) vanished();
      spdlog::warn("{}: cannot set {} ({})", settings_.path, name, std::strerror(errno));
      return false;
    }
    format_.controls_set.push_back(std::string(name) + "=" + std::to_string(c.value));
    return true;
  };
  if (settings_.lock_exposure) {
    if (!set(V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, "exposure_auto"))
      spdlog::warn("{}: cannot lock auto exposure; brightness may drift (radiometry assumes it is fixed)",
                   settings_.path);
  }
  if (settings_.exposure_100us >= 0) set(V4L2_CID_EXPOSURE_ABSOLUTE, settings_.exposure_100us, "exposure_absolute");
  if (settings_.gain >= 0) set(V4L2_CID_GAIN, settings_.gain, "gain");
  v4l2_control c{};
  c.id = V4L2_CID_EXPOSURE_ABSOLUTE;
  if (xioctl(*device_, fd_, VIDIOC_G_CTRL, &c) == 0 && c.value > 0) exposure_ = Nanos(c.value) * 100'000;
}

void V4l2Source::start_streaming() {
  v4l2_requestbuffers req{};
  req.count = __u32(settings_.buffers);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (xioctl(*device_, fd_, VIDIOC_REQBUFS, &req) < 0) fail_errno("VIDIOC_REQBUFS");
  if (req.count < 4)
    throw RuntimeError(settings_.path + ": the driver granted only " + std::to_string(req.count) +
                       " capture buffers; Lumar needs 4 to capture without stalls");
  for (__u32 i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (xioctl(*device_, fd_, VIDIOC_QUERYBUF, &b) < 0) fail_errno("VIDIOC_QUERYBUF");
    void* p = device_->mmap(b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, off_t(b.m.offset));
    if (p == MAP_FAILED) fail_errno("mmap of buffer " + std::to_string(i));
    buffers_.push_back({p, b.length});
  }
  format_.buffers = int(buffers_.size());
  for (__u32 i = 0; i < buffers_.size(); ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (xioctl(*device_, fd_, VIDIOC_QBUF, &b) < 0) fail_errno("VIDIOC_QBUF");
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(*device_, fd_, VIDIOC_STREAMON, &type) < 0) fail_errno("VIDIOC_STREAMON");
  streaming_ = true;
}

void V4l2Source::stop_streaming() noexcept {
  if (fd_ < 0) return;
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    xioctl(*device_, fd_, VIDIOC_STREAMOFF, &type);  // fails harmlessly after an unplug
    streaming_ = false;
  }
  for (const Buffer& b : buffers_) device_->munmap(b.start, b.length);
  buffers_.clear();
  if (!format_.fourcc.empty()) {  // release the buffers so the next open can have them
    v4l2_requestbuffers req{};
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    xioctl(*device_, fd_, VIDIOC_REQBUFS, &req);
  }
  device_->close(fd_);
  fd_ = -1;
}

bool V4l2Source::convert(const Buffer& buffer, std::size_t bytes_used, cv::Mat& bgr, ChromaSampling& chroma) {
  const int w = format_.width, h = format_.height;
  const auto* data = static_cast<std::uint8_t*>(buffer.start);
  bytes_used = std::min(bytes_used, buffer.length);
  const std::string& f = format_.fourcc;
  if (f == "MJPG" || f == "JPEG") {
    if (bytes_used == 0) return false;
    bgr = decode_jpeg({data, bytes_used}).bgr;
    chroma = chroma_sampling_of_jpeg({data, bytes_used});
    return !bgr.empty() && bgr.cols == w && bgr.rows == h;
  }
  const int channels = f == "YUYV" ? 2 : 3;
  const std::size_t stride =
      format_.bytes_per_line > 0 ? std::size_t(format_.bytes_per_line) : std::size_t(w) * channels;
  if (stride < std::size_t(w) * channels || bytes_used < stride * std::size_t(h)) return false;
  const cv::Mat raw(h, w, channels == 2 ? CV_8UC2 : CV_8UC3, const_cast<std::uint8_t*>(data), stride);
  chroma = f == "YUYV" ? ChromaSampling{2, 1} : ChromaSampling{};
  if (f == "YUYV")
    cv::cvtColor(raw, bgr, cv::COLOR_YUV2BGR_YUYV);
  else if (f == "RGB3")
    cv::cvtColor(raw, bgr, cv::COLOR_RGB2BGR);
  else
    bgr = raw.clone();  // BGR3: the buffer goes back to the driver, so copy
  return true;
}

bool V4l2Source::read(Frame& frame) {
  if (fd_ < 0) vanished();
  Nanos waited = 0;
  int corrupt_run = 0;
  for (;;) {
    pollfd p{fd_, POLLIN, 0};
    const int timeout_ms = int((settings_.poll_timeout + 999'999) / 1'000'000);
    const int r = device_->poll(&p, 1, timeout_ms);
    if (r < 0) {
      if (errno == EINTR) continue;
      fail_errno("poll");
    }
    if (r == 0) {
      ++stats_.poll_timeouts;
      waited += settings_.poll_timeout;
      if (waited >= settings_.frame_timeout)
        throw RuntimeError(settings_.path + ": no frame for " + std::to_string(nanos_to_seconds(waited)).substr(0, 4) +
                           " s; the camera stalled (check the cable, the light, or lower the resolution)");
      continue;
    }
    if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) vanished();

    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (xioctl(*device_, fd_, VIDIOC_DQBUF, &b) < 0) {
      if (errno == EAGAIN) {  // poll woke us but the frame is not ready after all
        ++stats_.eagain;
        continue;
      }
      fail_errno("VIDIOC_DQBUF");
    }
    if (b.index >= buffers_.size())
      throw RuntimeError(settings_.path + ": the driver returned buffer " + std::to_string(b.index) + " of " +
                         std::to_string(buffers_.size()));
    const Nanos dequeued = monotonic_now();

    const std::int64_t seq = std::int64_t(b.sequence);
    if (last_sequence_ < 0) {
      index_offset_ = -seq;  // indices count from the first frame
    } else if (seq > last_sequence_ + 1) {
      stats_.dropped += std::uint64_t(seq - last_sequence_ - 1);
    } else if (seq <= last_sequence_) {
      index_offset_ = last_sequence_ + index_offset_ + 1 - seq;  // the driver restarted its count
    }
    last_sequence_ = seq;

    cv::Mat bgr;
    ChromaSampling chroma;
    const bool good = !(b.flags & V4L2_BUF_FLAG_ERROR) && convert(buffers_[b.index], b.bytesused, bgr, chroma);
    // The buffer goes back at once, whatever happened to its contents.
    if (xioctl(*device_, fd_, VIDIOC_QBUF, &b) < 0) fail_errno("VIDIOC_QBUF");
    if (!good) {
      ++stats_.corrupt;
      if (++corrupt_run >= kMaxCorruptRun)
        throw RuntimeError(settings_.path + ": " + std::to_string(corrupt_run) + " " + format_.fourcc +
                           " frames in a row could not be decoded; try another --format");
      continue;
    }

    Nanos t;
    if ((b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) {
      t = timeval_nanos(b.timestamp);
      if ((b.flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) == V4L2_BUF_FLAG_TSTAMP_SRC_SOE)
        t += exposure_ / 2;
      else
        t -= exposure_ / 2;
    } else {
      t = dequeued;
      ++stats_.dequeue_stamped;
    }
    t = std::max(t, last_time_ + 1);  // a FrameSource's times increase
    last_time_ = t;
    frame.image = bgr;
    frame.chroma = chroma;
    frame.time = t;
    frame.index = seq + index_offset_;
    ++stats_.frames;
    return true;
  }
}

}  // namespace lumar::capture
