#include "pty_device.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

#include "lumar/base/error.h"

namespace lumar::tracking {

namespace {

std::string errno_text() { return std::strerror(errno); }

}  // namespace

PtyDevice::PtyDevice(const std::filesystem::path& link) : link_(link) {
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (master_ < 0) throw RuntimeError("emulator: cannot create a pseudo-terminal (" + errno_text() + ")");
  char name[PATH_MAX];
  if (::grantpt(master_) != 0 || ::unlockpt(master_) != 0 || ::ptsname_r(master_, name, sizeof name) != 0) {
    const std::string why = errno_text();
    ::close(master_);
    throw RuntimeError("emulator: cannot unlock the pseudo-terminal (" + why + ")");
  }
  slave_path_ = name;
  // On Linux the master's termios calls act on the slave: make it a raw 8-bit line
  // before any driver opens it, so nothing is echoed or translated meanwhile.
  termios t{};
  if (::tcgetattr(master_, &t) == 0) {
    ::cfmakeraw(&t);
    ::cfsetspeed(&t, B115200);
    ::tcsetattr(master_, TCSANOW, &t);
  }
  slave_ = ::open(name, O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (slave_ < 0) {
    const std::string why = errno_text();
    ::close(master_);
    throw RuntimeError("emulator: cannot open " + slave_path_ + " (" + why + ")");
  }
  if (!link_.empty()) {
    const std::filesystem::path tmp = link_.string() + ".tmp";
    ::unlink(tmp.c_str());
    if (::symlink(name, tmp.c_str()) != 0 || ::rename(tmp.c_str(), link_.c_str()) != 0) {
      const std::string why = errno_text();
      ::unlink(tmp.c_str());
      ::close(slave_);
      ::close(master_);
      throw RuntimeError(link_.string() + ": cannot create the link to " + slave_path_ + " (" + why +
                         "); check that its folder exists and is writable");
    }
  }
}

PtyDevice::~PtyDevice() { close(); }

void PtyDevice::close() {
  if (!link_.empty()) {
    // Only remove the link if it is still ours (another emulator may have taken it).
    char target[PATH_MAX];
    const ssize_t n = ::readlink(link_.c_str(), target, sizeof target - 1);
    if (n > 0 && std::string(target, std::size_t(n)) == slave_path_) ::unlink(link_.c_str());
    link_.clear();
  }
  if (slave_ >= 0) ::close(slave_);
  if (master_ >= 0) ::close(master_);
  slave_ = master_ = -1;
}

}  // namespace lumar::tracking
