#pragma once
// ByteTransport over a serial port (RS-232, a USB-serial adapter, or a pty) through
// LibSerial 1.0.0: baud, 8N1, optional RTS/CTS.
//
// Two LibSerial 1.0.0 traits are worked around here:
//  - Open() sets TIOCEXCL and never clears it, so a non-root process could not reopen
//    the port after a reconnect; the exclusive flag is cleared (TIOCNXCL) right after
//    opening.
//  - Read(buffer, 0, timeout) always ends by throwing ReadTimeout, and a hung-up line
//    can look like "no data yet". So read() waits with poll() (which reports a hang-up
//    as POLLHUP), asks how many bytes are there, and has LibSerial read exactly those.
#include <memory>
#include <string>
#include <vector>

#include "lumar/tracking/byte_transport.h"

namespace lumar::tracking {

struct SerialSettings {
  std::string path;      // "/dev/ttyUSB0", "/dev/pts/3", or a symlink to one
  int baud = 115200;     // one of supported_bauds()
  bool rts_cts = false;  // hardware flow control
};

// Baud rates the port can be set to (1200 ... 230400).
const std::vector<int>& supported_bauds();

class SerialTransport final : public ByteTransport {
 public:
  // Opens and configures the port. Throws InputError for a baud that is not supported,
  // DeviceVanished when the path does not exist (yet), RuntimeError when it cannot be
  // opened (permissions, in use) or configured.
  explicit SerialTransport(SerialSettings settings);
  ~SerialTransport() override;

  ByteChunk read(Nanos timeout) override;
  void write(std::string_view bytes, Nanos timeout) override;
  void discard_input() override;
  void close() override;
  bool is_open() const override;
  int baud() const override { return settings_.baud; }
  const std::string& name() const override { return settings_.path; }

 private:
  struct Port;  // keeps LibSerial out of this header
  // Closes and destroys a port, also one whose line hung up (see the .cpp).
  static void close_port(std::unique_ptr<Port>& port);
  SerialSettings settings_;
  std::unique_ptr<Port> port_;
};

}  // namespace lumar::tracking
