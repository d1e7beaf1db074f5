#pragma once
// The seam between the V4L2 capture code and the kernel: the six calls a V4L2
// program makes, with the system calls' own conventions (return -1 and set errno;
// mmap returns MAP_FAILED). The real device goes through libv4l2, which also
// converts formats the camera cannot deliver itself; tests script a device behind
// the same calls (formats, buffers, sequence gaps, EAGAIN, slow frames, ENODEV), so
// the capture code they run is the code that talks to a camera.
#include <poll.h>
#include <sys/types.h>

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace lumar::capture {

class V4l2Device {
 public:
  virtual ~V4l2Device() = default;
  virtual int open(const std::string& path, int flags) = 0;
  virtual int close(int fd) = 0;
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  virtual void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) = 0;
  virtual int munmap(void* address, std::size_t length) = 0;
  virtual int poll(pollfd* fds, nfds_t count, int timeout_ms) = 0;
};

// v4l2_open / v4l2_ioctl / v4l2_mmap / v4l2_munmap / v4l2_close and poll(2).
std::unique_ptr<V4l2Device> libv4l2_device();

// ioctl that retries on EINTR, as every V4L2 program must.
int xioctl(V4l2Device& device, int fd, unsigned long request, void* arg);

// What one /dev/videoN says about itself.
struct V4l2DeviceInfo {
  std::string path;  // "/dev/video0"
  std::string card, driver, bus;
  bool video_capture = false;  // V4L2_CAP_VIDEO_CAPTURE (metadata nodes have not)
  bool streaming = false;      // V4L2_CAP_STREAMING (mmap)
  std::string problem;         // why it could not be opened or queried ("" = it could)
};

// /dev/video* in `dev_dir` (numerically sorted), each opened and asked VIDIOC_QUERYCAP.
// Never throws; a node that cannot be opened says why in `problem`.
std::vector<V4l2DeviceInfo> list_v4l2_devices(V4l2Device& device, const std::filesystem::path& dev_dir = "/dev");

}  // namespace lumar::capture
