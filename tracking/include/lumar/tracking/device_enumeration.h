#pragma once
// What trackers could be plugged in: serial ports that exist, Polhemus USB devices
// (vendor 0x0f44) and USB-serial adapters (an ISOTRAK II is RS-232 only and shows up
// through one as /dev/ttyUSB*), found through libusb and /sys.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace lumar::tracking {

constexpr std::uint16_t kPolhemusVendor = 0x0f44;

struct SerialPortInfo {
  std::string path;         // "/dev/ttyUSB0"
  std::string description;  // "16550A UART", "USB 0403:6001", "USB CDC ACM"
};

struct UsbDeviceInfo {
  std::uint16_t vendor = 0, product = 0;
  int bus = 0, address = 0;
  std::string kind;  // "Polhemus Fastrak", "USB-serial adapter (FTDI)"
};

struct DeviceInventory {
  std::vector<SerialPortInfo> serial_ports;
  std::vector<UsbDeviceInfo> polhemus;    // vendor 0x0f44
  std::vector<UsbDeviceInfo> usb_serial;  // known USB-serial adapter vendors
  std::string usb_problem;                // why libusb could not list devices ("" = it could)
};

// "Polhemus Fastrak" (0x0002), "Polhemus Patriot" (0xef12), "Polhemus Liberty"
// (0xff12), "Polhemus device 0x1234" for another product of vendor 0x0f44; nullopt for
// any other vendor.
std::optional<std::string> polhemus_model(std::uint16_t vendor, std::uint16_t product);

// "FTDI" (0x0403), "Prolific" (0x067b), "CH340" (0x1a86), "Silicon Labs CP210x"
// (0x10c4); nullopt for other vendors.
std::optional<std::string> usb_serial_vendor(std::uint16_t vendor);

// Serial ports: /dev/ttyUSB* and /dev/ttyACM* that exist, and /dev/ttyS* that have a
// UART behind them (TIOCGSERIAL type is not PORT_UNKNOWN). USB devices through libusb;
// when libusb cannot list them (no USB bus, no permission), usb_problem says why.
// Never throws.
DeviceInventory list_devices();

}  // namespace lumar::tracking
