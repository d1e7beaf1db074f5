#include "lumar/capture/v4l2_device.h"

#include <fcntl.h>
#include <libv4l2.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace lumar::capture {

namespace {

class Libv4l2Device final : public V4l2Device {
 public:
  int open(const std::string& path, int flags) override { return v4l2_open(path.c_str(), flags); }
  int close(int fd) override { return v4l2_close(fd); }
  int ioctl(int fd, unsigned long request, void* arg) override { return v4l2_ioctl(fd, request, arg); }
  void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset) override {
    return v4l2_mmap(nullptr, length, prot, flags, fd, offset);
  }
  int munmap(void* address, std::size_t length) override { return v4l2_munmap(address, length); }
  int poll(pollfd* fds, nfds_t count, int timeout_ms) override { return ::poll(fds, count, timeout_ms); }
};

std::string c_string(const __u8* text, std::size_t size) {
  const auto* begin = reinterpret_cast<const char*>(text);
  return std::string(begin, strnlen(begin, size));
}

// "video12" -> 12, anything else -> -1.
int video_number(const std::string& name) {
  if (name.rfind("video", 0) != 0 || name.size() == 5) return -1;
  int n = 0;
  for (char c : name.substr(5)) {
    if (c < '0' || c > '9') return -1;
    n = n * 10 + (c - '0');
  }
  return n;
}

}  // namespace

std::unique_ptr<V4l2Device> libv4l2_device() { return std::make_unique<Libv4l2Device>(); }

int xioctl(V4l2Device& device, int fd, unsigned long request, void* arg) {
  int r;
  do r = device.ioctl(fd, request, arg);
  while (r == -1 && errno == EINTR);
  return r;
}

std::vector<V4l2DeviceInfo> list_v4l2_devices(V4l2Device& device, const std::filesystem::path& dev_dir) {
  std::vector<std::pair<int, std::filesystem::path>> nodes;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(dev_dir, ec); !ec && it != std::filesystem::directory_iterator();
       it.increment(ec)) {
    const int n = video_number(it->path().filename().string());
    if (n >= 0) nodes.emplace_back(n, it->path());
  }
  std::sort(nodes.begin(), nodes.end());
  std::vector<V4l2DeviceInfo> out;
  for (const auto& [n, path] : nodes) {
    V4l2DeviceInfo info;
    info.path = path.string();
    const int fd = device.open(info.path, O_RDWR | O_NONBLOCK);
    if (fd < 0) {
      info.problem = std::string("cannot open: ") + std::strerror(errno);
      out.push_back(info);
      continue;
    }
    v4l2_capability cap{};
    if (xioctl(device, fd, VIDIOC_QUERYCAP, &cap) < 0) {
      info.problem = std::string("VIDIOC_QUERYCAP failed: ") + std::strerror(errno);
    } else {
      info.card = c_string(cap.card, sizeof cap.card);
      info.driver = c_string(cap.driver, sizeof cap.driver);
      info.bus = c_string(cap.bus_info, sizeof cap.bus_info);
      // device_caps describes this node; capabilities the whole physical device.
      const __u32 caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
      info.video_capture = caps & V4L2_CAP_VIDEO_CAPTURE;
      info.streaming = caps & V4L2_CAP_STREAMING;
    }
    device.close(fd);
    out.push_back(info);
  }
  return out;
}

}  // namespace lumar::capture
