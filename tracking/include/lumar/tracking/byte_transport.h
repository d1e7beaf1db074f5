#pragma once
// The line to a tracker, whatever carries it (a serial port, a USB-serial adapter, a
// pty from the emulator). The driver only ever sees this interface, so tests drive
// the same code a real device would.
#include <string>
#include <string_view>

#include "lumar/base/error.h"
#include "lumar/base/time.h"
#include "lumar/tracking/byte_chunk.h"

namespace lumar::tracking {

// The device is gone (adapter unplugged, pty closed, port not there): close and
// reopen later. Distinct from other RuntimeErrors so that callers can retry quietly.
struct DeviceVanished : RuntimeError {
  using RuntimeError::RuntimeError;
};

class ByteTransport {
 public:
  virtual ~ByteTransport() = default;

  // Waits at most `timeout` for bytes and returns every byte that was there (an empty
  // chunk after a timeout). chunk.arrival is CLOCK_MONOTONIC when the read returned,
  // i.e. no earlier than the arrival of the chunk's last byte.
  // Throws DeviceVanished when the device went away, RuntimeError for other failures.
  virtual ByteChunk read(Nanos timeout) = 0;

  // Sends every byte, waiting at most `timeout` for room in the output buffer (RTS/CTS
  // can hold it). Throws DeviceVanished, or RuntimeError when the line stays blocked.
  virtual void write(std::string_view bytes, Nanos timeout) = 0;

  // Drops bytes that arrived but were not read yet.
  virtual void discard_input() = 0;

  // Idempotent, never throws. read/write after close throw DeviceVanished.
  virtual void close() = 0;

  virtual bool is_open() const = 0;
  virtual int baud() const = 0;
  // What to name in messages, e.g. "/dev/ttyUSB0".
  virtual const std::string& name() const = 0;
};

}  // namespace lumar::tracking
