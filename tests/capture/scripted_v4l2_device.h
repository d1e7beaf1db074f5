#pragma once
// A camera behind the V4l2Device seam, driven by a script, so that the real V4L2
// capture code can be run without hardware. It keeps the kernel's rules that the
// capture code relies on: buffers must be queued to be filled, DQBUF hands back a
// filled one with its sequence number, timestamp and flags, an unplugged device
// answers ENODEV / POLLERR. Poll timeouts do not really wait (tests stay fast).
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "lumar/base/time.h"
#include "lumar/capture/v4l2_device.h"

namespace lumar::test {

struct ScriptStep {
  enum Kind { Frame, Timeout, Eagain, UnplugPoll, UnplugDqbuf } kind = Frame;
  std::uint32_t sequence = 0;
  Nanos timestamp = 0;
  std::vector<std::uint8_t> payload;
  bool error_flag = false;
};

struct ScriptedCamera {
  std::set<std::string> paths{"/dev/video0"};
  std::set<std::string> unopenable;  // open() gives EACCES
  std::uint32_t device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<std::pair<std::string, bool>> formats{{"YUYV", false}, {"MJPG", false}};  // fourcc, emulated
  int width = 64, height = 48;                                                          // the only size it has
  std::uint32_t timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_EOF;
  std::uint32_t max_buffers = 8;
  bool has_exposure_controls = true;
  int exposure_100us = 100;  // 10 ms
  std::deque<ScriptStep> steps;
};

class ScriptedV4l2Device final : public capture::V4l2Device {
 public:
  explicit ScriptedV4l2Device(ScriptedCamera camera) : cam_(std::move(camera)) {}

  // What the capture code did, for the tests to check.
  struct Log {
    int opens = 0, closes = 0, maps = 0, unmaps = 0, polls = 0;
    bool streamed_on = false, streamed_off = false;
    std::uint32_t buffers_requested = 0, buffers_granted = 0;
    std::uint32_t chosen_format = 0;
    std::map<std::uint32_t, int> controls;  // id -> value set
  };
  // Shared, so that it outlives the device (which the V4l2Source owns and destroys).
  std::shared_ptr<const Log> log() const { return log_ptr_; }
  const ScriptedCamera& camera() const { return cam_; }

  int open(const std::string& path, int) override {
    if (cam_.unopenable.count(path)) return fail(EACCES);
    if (!cam_.paths.count(path)) return fail(ENOENT);
    ++log_.opens;
    return kFd;
  }
  int close(int fd) override {
    if (fd != kFd) return fail(EBADF);
    ++log_.closes;
    return 0;
  }
  void* mmap(std::size_t length, int, int, int fd, off_t offset) override {
    const std::size_t i = std::size_t(offset) / kPage;
    if (fd != kFd || i >= buffers_.size() || length != buffers_[i].size()) {
      errno = EINVAL;
      return MAP_FAILED;
    }
    ++log_.maps;
    return buffers_[i].data();
  }
  int munmap(void*, std::size_t) override {
    ++log_.unmaps;
    return 0;
  }
  int poll(pollfd* fds, nfds_t, int) override {
    ++log_.polls;
    fds[0].revents = 0;
    if (unplugged_) {
      fds[0].revents = POLLERR | POLLHUP;
      return 1;
    }
    if (cam_.steps.empty() || !streaming_) return 0;  // the camera stalls
    ScriptStep& s = cam_.steps.front();
    switch (s.kind) {
      case ScriptStep::Timeout:
        cam_.steps.pop_front();
        return 0;
      case ScriptStep::UnplugPoll:
        cam_.steps.pop_front();
        unplugged_ = true;
        fds[0].revents = POLLERR | POLLHUP;
        return 1;
      default:
        if (s.kind == ScriptStep::Frame && queued_.empty()) return 0;  // no buffer to fill
        fds[0].revents = POLLIN;
        return 1;
    }
  }

  int ioctl(int fd, unsigned long request, void* arg) override {
    if (fd != kFd) return fail(EBADF);
    if (unplugged_ && request != VIDIOC_STREAMOFF && request != VIDIOC_REQBUFS) return fail(ENODEV);
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* c = static_cast<v4l2_capability*>(arg);
        *c = {};
        std::strcpy(reinterpret_cast<char*>(c->driver), "scripted");
        std::strcpy(reinterpret_cast<char*>(c->card), "Scripted camera");
        std::strcpy(reinterpret_cast<char*>(c->bus_info), "test:0");
        c->capabilities = cam_.device_caps | V4L2_CAP_DEVICE_CAPS;
        c->device_caps = cam_.device_caps;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* d = static_cast<v4l2_fmtdesc*>(arg);
        if (d->index >= cam_.formats.size()) return fail(EINVAL);
        const auto& [f, emulated] = cam_.formats[d->index];
        d->pixelformat = code(f);
        d->flags = emulated ? V4L2_FMT_FLAG_EMULATED : 0;
        return 0;
      }
      case VIDIOC_S_FMT: {
        auto* f = static_cast<v4l2_format*>(arg);
        bool offered = false;
        for (const auto& o : cam_.formats) offered |= code(o.first) == f->fmt.pix.pixelformat;
        if (!offered) f->fmt.pix.pixelformat = code(cam_.formats.front().first);
        f->fmt.pix.width = std::uint32_t(cam_.width);
        f->fmt.pix.height = std::uint32_t(cam_.height);
        const std::uint32_t pf = f->fmt.pix.pixelformat;
        f->fmt.pix.bytesperline = pf == code("YUYV") ? 2 * cam_.width : pf == code("MJPG") ? 0 : 3 * cam_.width;
        log_.chosen_format = pf;
        return 0;
      }
      case VIDIOC_G_PARM: {
        auto* p = static_cast<v4l2_streamparm*>(arg);
        p->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
        p->parm.capture.timeperframe = tpf_;
        return 0;
      }
      case VIDIOC_S_PARM:
        tpf_ = static_cast<v4l2_streamparm*>(arg)->parm.capture.timeperframe;
        return 0;
      case VIDIOC_QUERYCTRL: {
        auto* q = static_cast<v4l2_queryctrl*>(arg);
        if (!cam_.has_exposure_controls) return fail(EINVAL);
        if (q->id == V4L2_CID_EXPOSURE_AUTO)
          q->minimum = 0, q->maximum = 3;
        else if (q->id == V4L2_CID_EXPOSURE_ABSOLUTE)
          q->minimum = 1, q->maximum = 5000;
        else if (q->id == V4L2_CID_GAIN)
          q->minimum = 0, q->maximum = 255;
        else
          return fail(EINVAL);
        return 0;
      }
      case VIDIOC_S_CTRL: {
        auto* c = static_cast<v4l2_control*>(arg);
        log_.controls[c->id] = c->value;
        if (c->id == V4L2_CID_EXPOSURE_ABSOLUTE) cam_.exposure_100us = c->value;
        return 0;
      }
      case VIDIOC_G_CTRL: {
        auto* c = static_cast<v4l2_control*>(arg);
        if (!cam_.has_exposure_controls || c->id != V4L2_CID_EXPOSURE_ABSOLUTE) return fail(EINVAL);
        c->value = cam_.exposure_100us;
        return 0;
      }
      case VIDIOC_REQBUFS: {
        auto* r = static_cast<v4l2_requestbuffers*>(arg);
        if (r->memory != V4L2_MEMORY_MMAP) return fail(EINVAL);
        if (r->count == 0) {
          buffers_.clear();
          queued_.clear();
          return 0;
        }
        log_.buffers_requested = r->count;
        r->count = std::min(r->count, cam_.max_buffers);
        log_.buffers_granted = r->count;
        buffers_.assign(r->count, std::vector<std::uint8_t>(buffer_bytes()));
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return fail(EINVAL);
        b->length = std::uint32_t(buffers_[b->index].size());
        b->m.offset = b->index * kPage;
        return 0;
      }
      case VIDIOC_QBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return fail(EINVAL);
        queued_.push_back(b->index);
        return 0;
      }
      case VIDIOC_DQBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (cam_.steps.empty() || !streaming_) return fail(EAGAIN);
        ScriptStep s = cam_.steps.front();
        if (s.kind == ScriptStep::Eagain) {
          cam_.steps.pop_front();
          return fail(EAGAIN);
        }
        if (s.kind == ScriptStep::UnplugDqbuf) {
          cam_.steps.pop_front();
          unplugged_ = true;
          return fail(ENODEV);
        }
        if (s.kind != ScriptStep::Frame || queued_.empty()) return fail(EAGAIN);
        cam_.steps.pop_front();
        const std::uint32_t i = queued_.front();
        queued_.pop_front();
        auto& buf = buffers_[i];
        std::memcpy(buf.data(), s.payload.data(), std::min(buf.size(), s.payload.size()));
        b->index = i;
        b->bytesused = std::uint32_t(std::min(buf.size(), s.payload.size()));
        b->sequence = s.sequence;
        b->timestamp.tv_sec = s.timestamp / 1'000'000'000;
        b->timestamp.tv_usec = (s.timestamp % 1'000'000'000) / 1000;
        b->flags = cam_.timestamp_flags | (s.error_flag ? V4L2_BUF_FLAG_ERROR : 0);
        return 0;
      }
      case VIDIOC_STREAMON:
        streaming_ = log_.streamed_on = true;
        return 0;
      case VIDIOC_STREAMOFF:
        streaming_ = false;
        log_.streamed_off = true;
        return 0;
      default:
        return fail(ENOTTY);
    }
  }

  static std::uint32_t code(const std::string& f) {
    std::string t = f;
    t.resize(4, ' ');
    return v4l2_fourcc(t[0], t[1], t[2], t[3]);
  }

 private:
  static constexpr int kFd = 42;
  static constexpr std::uint32_t kPage = 4096;
  static int fail(int e) {
    errno = e;
    return -1;
  }
  std::size_t buffer_bytes() const { return std::size_t(cam_.width) * cam_.height * 3 + 4096; }

  ScriptedCamera cam_;
  std::shared_ptr<Log> log_ptr_ = std::make_shared<Log>();
  Log& log_ = *log_ptr_;
  std::vector<std::vector<std::uint8_t>> buffers_;
  std::deque<std::uint32_t> queued_;
  bool streaming_ = false, unplugged_ = false;
  v4l2_fract tpf_{1, 30};
};

}  // namespace lumar::test
