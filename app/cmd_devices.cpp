// lumar devices: what a tracker could be plugged into: serial ports, Polhemus USB
// devices (vendor 0x0f44) and USB-serial adapters; and the V4L2 cameras.
#include <cstdio>

#include "commands.h"
#include "lumar/capture/v4l2_device.h"
#include "lumar/tracking/device_enumeration.h"

namespace lumar::app {

namespace {

void print_usb(const tracking::UsbDeviceInfo& d) {
  std::printf("  %04x:%04x  bus %03d device %03d  %s\n", d.vendor, d.product, d.bus, d.address, d.kind.c_str());
}

void run_devices() {
  const tracking::DeviceInventory inv = tracking::list_devices();
  std::printf("Serial ports:\n");
  if (inv.serial_ports.empty()) std::printf("  none (no /dev/ttyUSB*, /dev/ttyACM*, or /dev/ttyS* with a UART)\n");
  for (const auto& p : inv.serial_ports) std::printf("  %-16s %s\n", p.path.c_str(), p.description.c_str());

  std::printf("Polhemus USB devices (vendor 0f44):\n");
  if (!inv.usb_problem.empty())
    std::printf("  unknown: %s\n", inv.usb_problem.c_str());
  else if (inv.polhemus.empty())
    std::printf("  none\n");
  for (const auto& d : inv.polhemus) print_usb(d);

  std::printf("USB-serial adapters (FTDI, Prolific, CH340, CP210x):\n");
  if (!inv.usb_problem.empty())
    std::printf("  unknown: %s\n", inv.usb_problem.c_str());
  else if (inv.usb_serial.empty())
    std::printf("  none\n");
  for (const auto& d : inv.usb_serial) print_usb(d);

  std::printf("V4L2 cameras:\n");
  const auto device = capture::libv4l2_device();
  const auto cameras = capture::list_v4l2_devices(*device);
  if (cameras.empty()) std::printf("  none (no /dev/video*)\n");
  for (const auto& c : cameras) {
    if (!c.problem.empty())
      std::printf("  %-16s %s\n", c.path.c_str(), c.problem.c_str());
    else
      std::printf("  %-16s %s (%s, %s)%s\n", c.path.c_str(), c.card.c_str(), c.driver.c_str(), c.bus.c_str(),
                  c.video_capture && c.streaming ? "" : "  [not a streaming capture node]");
  }

  if (inv.polhemus.empty() && inv.usb_serial.empty())
    std::printf(
        "No tracker hardware found. An ISOTRAK II is RS-232 only: connect it to a serial port or a "
        "USB-serial adapter. To try the software without one: lumar tracker emulate --link /tmp/isotrak\n");
}

}  // namespace

void register_devices(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("devices", "List serial ports, Polhemus USB devices, USB-serial adapters and V4L2 cameras");
  add_action(cmd, [] { run_devices(); });
}

}  // namespace lumar::app
