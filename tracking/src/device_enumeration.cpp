#include "lumar/tracking/device_enumeration.h"

#include <fcntl.h>
#include <libusb-1.0/libusb.h>
#include <linux/serial.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>

namespace lumar::tracking {

namespace {
namespace fs = std::filesystem;

std::string hex4(unsigned v) {
  char s[8];
  std::snprintf(s, sizeof s, "%04x", v & 0xffff);
  return s;
}

std::string read_sys(const fs::path& p) {
  std::ifstream in(p);
  std::string s;
  std::getline(in, s);
  return s;
}

// "USB 0403:6001" from /sys/class/tty/<name>/device/../ (the USB device holds idVendor).
std::string usb_description(const std::string& tty_name) {
  std::error_code ec;
  fs::path dev = fs::canonical(fs::path("/sys/class/tty") / tty_name / "device", ec);
  for (int up = 0; !ec && up < 4 && !dev.empty(); ++up, dev = dev.parent_path()) {
    const std::string vendor = read_sys(dev / "idVendor");
    const std::string product = read_sys(dev / "idProduct");
    if (!vendor.empty() && !product.empty()) return "USB " + vendor + ":" + product;
  }
  return "USB";
}

// The UART type of a /dev/ttyS* port, or "" when there is no UART behind it.
std::string uart_type(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) return "";
  serial_struct info{};
  const bool ok = ::ioctl(fd, TIOCGSERIAL, &info) == 0;
  ::close(fd);
  if (!ok || info.type == PORT_UNKNOWN) return "";
  switch (info.type) {
    case PORT_8250:
      return "8250 UART";
    case PORT_16450:
      return "16450 UART";
    case PORT_16550:
      return "16550 UART";
    case PORT_16550A:
      return "16550A UART";
    default:
      return "UART type " + std::to_string(info.type);
  }
}

std::vector<SerialPortInfo> list_serial_ports() {
  std::vector<SerialPortInfo> ports;
  static const std::regex usb(R"(ttyUSB[0-9]+)"), acm(R"(ttyACM[0-9]+)"), builtin(R"(ttyS[0-9]+)");
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/dev", ec)) {
    const std::string name = entry.path().filename().string();
    if (std::regex_match(name, usb)) {
      ports.push_back({entry.path().string(), usb_description(name)});
    } else if (std::regex_match(name, acm)) {
      ports.push_back({entry.path().string(), usb_description(name) + " (CDC ACM)"});
    } else if (std::regex_match(name, builtin)) {
      const std::string type = uart_type(entry.path().string());
      if (!type.empty()) ports.push_back({entry.path().string(), type});
    }
  }
  std::sort(ports.begin(), ports.end(), [](const auto& a, const auto& b) { return a.path < b.path; });
  return ports;
}

}  // namespace

std::optional<std::string> polhemus_model(std::uint16_t vendor, std::uint16_t product) {
  if (vendor != kPolhemusVendor) return std::nullopt;
  switch (product) {
    case 0x0002:
      return "Polhemus Fastrak";
    case 0xef12:
      return "Polhemus Patriot";
    case 0xff12:
      return "Polhemus Liberty";
  }
  return "Polhemus device 0x" + hex4(product);
}

std::optional<std::string> usb_serial_vendor(std::uint16_t vendor) {
  switch (vendor) {
    case 0x0403:
      return "FTDI";
    case 0x067b:
      return "Prolific";
    case 0x1a86:
      return "CH340";
    case 0x10c4:
      return "Silicon Labs CP210x";
  }
  return std::nullopt;
}

DeviceInventory list_devices() {
  DeviceInventory inv;
  try {
    inv.serial_ports = list_serial_ports();
  } catch (const std::exception&) {
    // A /dev that cannot be listed leaves the list empty; nothing to report beyond that.
  }

  libusb_context* ctx = nullptr;
  if (int rc = libusb_init(&ctx); rc != 0) {
    inv.usb_problem = std::string("libusb cannot start: ") + libusb_strerror(libusb_error(rc));
    return inv;
  }
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx, &list);
  if (n < 0) {
    inv.usb_problem = std::string("libusb cannot list devices: ") + libusb_strerror(libusb_error(n));
  } else {
    for (ssize_t i = 0; i < n; ++i) {
      libusb_device_descriptor d{};
      if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
      UsbDeviceInfo info;
      info.vendor = d.idVendor;
      info.product = d.idProduct;
      info.bus = libusb_get_bus_number(list[i]);
      info.address = libusb_get_device_address(list[i]);
      if (auto model = polhemus_model(d.idVendor, d.idProduct)) {
        info.kind = *model;
        inv.polhemus.push_back(info);
      } else if (auto vendor = usb_serial_vendor(d.idVendor)) {
        info.kind = "USB-serial adapter (" + *vendor + ")";
        inv.usb_serial.push_back(info);
      }
    }
    libusb_free_device_list(list, 1);
  }
  libusb_exit(ctx);
  return inv;
}

}  // namespace lumar::tracking
