#pragma once
// The device end of a pseudo-terminal, for the emulator. Raw termios is set here with
// plain termios calls (LibSerial only opens the slave end, the driver's side).
//
// The emulator keeps its own descriptor of the slave open: without one, the master
// reports a hang-up whenever the driver closes the port, and the device would vanish
// each time the driver reconnects.
#include <filesystem>
#include <string>

namespace lumar::tracking {

class PtyDevice {
 public:
  // Opens a new pty in raw mode, non-blocking master, and points `link` at its slave
  // when link is not empty (replacing an old link atomically). RuntimeError on failure.
  explicit PtyDevice(const std::filesystem::path& link);
  ~PtyDevice();  // close()
  PtyDevice(const PtyDevice&) = delete;
  PtyDevice& operator=(const PtyDevice&) = delete;

  int master_fd() const { return master_; }
  const std::string& slave_path() const { return slave_path_; }

  // Removes the link (if it still points here), closes both ends: a program holding
  // the slave sees a hang-up. Idempotent.
  void close();

 private:
  std::filesystem::path link_;
  std::string slave_path_;
  int master_ = -1, slave_ = -1;
};

}  // namespace lumar::tracking
