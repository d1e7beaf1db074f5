#include "lumar/tracking/serial_transport.h"

#include <fcntl.h>
#include <libserial/SerialPort.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

namespace lumar::tracking {

namespace {

// Largest read handed to LibSerial at once; more waits for the next read().
constexpr int kMaxReadBytes = 4096;

LibSerial::BaudRate to_libserial_baud(int baud) {
  using B = LibSerial::BaudRate;
  switch (baud) {
    case 1200:
      return B::BAUD_1200;
    case 2400:
      return B::BAUD_2400;
    case 4800:
      return B::BAUD_4800;
    case 9600:
      return B::BAUD_9600;
    case 19200:
      return B::BAUD_19200;
    case 38400:
      return B::BAUD_38400;
    case 57600:
      return B::BAUD_57600;
    case 115200:
      return B::BAUD_115200;
    case 230400:
      return B::BAUD_230400;
  }
  return B::BAUD_INVALID;
}

int poll_timeout_ms(Nanos timeout) {
  if (timeout <= 0) return 0;
  // Round up so that a 0.5 ms timeout still waits instead of spinning.
  return int(std::min<Nanos>((timeout + 999'999) / 1'000'000, 1'000'000));
}

// Waits until `fd` is ready for `events` or `timeout` has passed (returns 0 then),
// riding over signals; a hang-up is the device vanishing.
short wait_for(int fd, short events, Nanos timeout, const std::string& path) {
  const Nanos deadline = monotonic_now() + std::max<Nanos>(timeout, 0);
  pollfd p{fd, events, 0};
  int ready;
  for (;;) {
    ready = ::poll(&p, 1, poll_timeout_ms(deadline - monotonic_now()));
    if (ready >= 0 || errno != EINTR) break;
  }
  if (ready < 0) throw RuntimeError(path + ": poll failed (" + std::strerror(errno) + ")");
  if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) throw DeviceVanished(path + ": the device hung up or was unplugged");
  return ready == 0 ? 0 : p.revents;
}

}  // namespace

struct SerialTransport::Port {
  LibSerial::SerialPort serial;
  int fd = -1;
};

const std::vector<int>& supported_bauds() {
  static const std::vector<int> bauds{1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400};
  return bauds;
}

SerialTransport::SerialTransport(SerialSettings settings) : settings_(std::move(settings)) {
  const std::string& path = settings_.path;
  if (to_libserial_baud(settings_.baud) == LibSerial::BaudRate::BAUD_INVALID)
    throw InputError(path + ": baud " + std::to_string(settings_.baud) +
                     " is not supported; use one of 9600, 19200, 38400, 57600, 115200");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw DeviceVanished(path + ": no such serial port (" + std::strerror(errno) +
                         "); plug the device in or check the path");

  auto port = std::make_unique<Port>();
  try {
    port->serial.Open(path);
  } catch (const std::exception& e) {
    const int err = errno;
    std::string why = e.what();
    // Open() can fail after opening the descriptor (e.g. no termios on a non-tty).
    port->fd = port->serial.IsOpen() ? port->serial.GetFileDescriptor() : -1;
    if (port->fd >= 0) close_port(port);
    if (err == EACCES)
      throw RuntimeError(path + ": permission denied; add your user to the 'dialout' group and log in again");
    if (err == EBUSY) throw RuntimeError(path + ": in use by another program (exclusive); close it and retry");
    if (err == ENOTTY) throw RuntimeError(path + ": not a serial port; pick one from `lumar devices`");
    if (err == ENOENT || err == ENXIO || err == ENODEV || err == EIO)
      throw DeviceVanished(path + ": cannot open (" + why + "); the device is not there");
    throw RuntimeError(path + ": cannot open the serial port (" + why + ")");
  }
  port->fd = port->serial.GetFileDescriptor();
  // LibSerial set TIOCEXCL; without clearing it a non-root process could never
  // reopen this port after the watchdog closed it.
  ::ioctl(port->fd, TIOCNXCL);
  try {
    port->serial.SetBaudRate(to_libserial_baud(settings_.baud));
    port->serial.SetCharacterSize(LibSerial::CharacterSize::CHAR_SIZE_8);
    port->serial.SetParity(LibSerial::Parity::PARITY_NONE);
    port->serial.SetStopBits(LibSerial::StopBits::STOP_BITS_1);
    // Also flushes both directions: bytes queued while nobody listened are stale.
    port->serial.SetFlowControl(settings_.rts_cts ? LibSerial::FlowControl::FLOW_CONTROL_HARDWARE
                                                  : LibSerial::FlowControl::FLOW_CONTROL_NONE);
  } catch (const std::exception& e) {
    const std::string why = e.what();
    close_port(port);
    throw RuntimeError(path + ": cannot configure " + std::to_string(settings_.baud) + " baud 8N1 (" + why +
                       "); is this a serial port?");
  }
  port_ = std::move(port);
}

SerialTransport::~SerialTransport() { close(); }

bool SerialTransport::is_open() const { return port_ != nullptr; }

void SerialTransport::close() { close_port(port_); }

void SerialTransport::close_port(std::unique_ptr<Port>& port_) {
  if (!port_) return;
  try {
    port_->serial.Close();
    port_.reset();
    return;
  } catch (...) {
  }
  // LibSerial's Close() restores the old termios before closing; on a line that hung
  // up that fails, it throws and leaves the descriptor open, and the SerialPort
  // destructor would then throw again (std::terminate). Put a harmless tty (a fresh
  // pty master) under the same descriptor number so that Close() can finish.
  bool closed = false;
  const int stand_in = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (stand_in >= 0) {
    if (::dup2(stand_in, port_->fd) >= 0) {
      try {
        port_->serial.Close();
        closed = true;
      } catch (...) {
      }
    }
    ::close(stand_in);
  }
  if (closed) {
    port_.reset();
  } else {
    ::close(port_->fd);
    (void)port_.release();  // deliberately leaked: destroying it would terminate the program
  }
}

ByteChunk SerialTransport::read(Nanos timeout) {
  const std::string& path = settings_.path;
  if (!port_) throw DeviceVanished(path + ": the port is closed");
  const short revents = wait_for(port_->fd, POLLIN, timeout, path);
  ByteChunk chunk;
  if (!(revents & POLLIN)) {
    chunk.arrival = monotonic_now();
    return chunk;
  }
  int available = 0;
  try {
    available = port_->serial.GetNumberOfBytesAvailable();
  } catch (const std::exception& e) {
    throw DeviceVanished(path + ": the device vanished (" + e.what() + ")");
  }
  // Readable with nothing to read is how a tty reports end of file.
  if (available <= 0) throw DeviceVanished(path + ": end of file on the serial port");
  LibSerial::DataBuffer buffer;
  try {
    // Exactly the bytes already there: returns without waiting for its timeout.
    port_->serial.Read(buffer, std::size_t(std::min(available, kMaxReadBytes)), 100);
  } catch (const LibSerial::ReadTimeout&) {
    // Bytes announced by FIONREAD always arrive; keep whatever was read.
  } catch (const std::exception& e) {
    throw DeviceVanished(path + ": read failed (" + e.what() + ")");
  }
  chunk.arrival = monotonic_now();
  chunk.bytes.assign(buffer.begin(), buffer.end());
  return chunk;
}

void SerialTransport::write(std::string_view bytes, Nanos timeout) {
  const std::string& path = settings_.path;
  if (!port_) throw DeviceVanished(path + ": the port is closed");
  if (bytes.empty()) return;
  if (!(wait_for(port_->fd, POLLOUT, timeout, path) & POLLOUT))
    throw RuntimeError(path + ": cannot send for " + std::to_string(timeout / 1'000'000) +
                       " ms; the output is blocked (check RTS/CTS wiring or turn --rts-cts off)");
  try {
    port_->serial.Write(std::string(bytes));
  } catch (const std::exception& e) {
    throw DeviceVanished(path + ": write failed (" + e.what() + ")");
  }
}

void SerialTransport::discard_input() {
  if (!port_) return;
  try {
    port_->serial.FlushInputBuffer();
  } catch (const std::exception& e) {
    throw DeviceVanished(settings_.path + ": cannot flush input (" + e.what() + ")");
  }
}

}  // namespace lumar::tracking
