#include "lumar/tracking/record_codec.h"

#include <cmath>
#include <string_view>

#include "fastrak_binary.h"
#include "isotrak_binary.h"
#include "lumar/base/error.h"
#include "lumar/tracking/isotrak_ascii.h"

namespace lumar::tracking {

int station_count(Device device) { return device == Device::Fastrak ? 4 : 2; }

std::string device_name(Device device) { return device == Device::Fastrak ? "fastrak" : "isotrak2"; }

Device parse_device(const std::string& name) {
  if (name == "isotrak2") return Device::Isotrak2;
  if (name == "fastrak") return Device::Fastrak;
  throw InputError("tracker device '" + name + "' is unknown; use isotrak2 or fastrak");
}

std::vector<int> parse_output_list(const std::string& text) {
  std::vector<int> items;
  std::size_t at = 0;
  while (true) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string_view field = std::string_view(text).substr(at, comma - at);
    int value = 0;
    bool ok = !field.empty() && field.size() <= 3;
    for (char c : field) {
      ok = ok && c >= '0' && c <= '9';
      value = value * 10 + (c - '0');
    }
    if (!ok)
      throw InputError("output list '" + text + "' is not a comma-separated list of item numbers; use e.g. 2,4,1");
    items.push_back(value);
    if (comma == text.size()) break;
    at = comma + 1;
  }
  return items;
}

TrackerFormat TrackerFormat::of(Device device, bool binary, OutputFormat output) {
  TrackerFormat f;
  f.device = device;
  f.binary = binary;
  f.output = std::move(output);
  f.max_station = station_count(device);
  return f;
}

void validate_tracker_format(const TrackerFormat& format) {
  validate_output_format(format.output);
  if (format.max_station < 1 || format.max_station > 9)
    throw InputError("tracker format: max station " + std::to_string(format.max_station) +
                     " is outside 1..9; use 2 for an ISOTRAK II, 4 for a Fastrak");
  if (!(std::isfinite(format.euler_full_scale_deg) && format.euler_full_scale_deg > 0))
    throw InputError("tracker format: Euler full scale must be a positive number of degrees; use 180");
}

int record_length(const TrackerFormat& format) {
  validate_tracker_format(format);
  if (!format.binary) return ascii_record_length(format.output);
  return format.device == Device::Isotrak2 ? detail::isotrak_binary_record_length(format)
                                           : detail::fastrak_binary_record_length(format);
}

std::vector<std::uint8_t> encode_record(const IsotrakRecord& record, const TrackerFormat& format) {
  validate_tracker_format(format);
  if (format.binary)
    return format.device == Device::Isotrak2 ? detail::encode_isotrak_binary(record, format)
                                             : detail::encode_fastrak_binary(record, format);
  if (record.station < 1 || record.station > format.max_station)
    throw std::invalid_argument("ASCII encoder: station " + std::to_string(record.station) + " is outside 1.." +
                                std::to_string(format.max_station));
  const std::string s = encode_ascii_record(record, format.output);
  return std::vector<std::uint8_t>(s.begin(), s.end());
}

bool is_record_start(std::uint8_t first, std::uint8_t second, const TrackerFormat& format) {
  const std::uint8_t start = format.binary && format.device == Device::Isotrak2 ? 0x80 | '0' : '0';
  return first == start && second >= '1' && second <= '0' + format.max_station;
}

std::optional<IsotrakRecord> decode_record(std::span<const std::uint8_t> bytes, const TrackerFormat& format) {
  validate_tracker_format(format);
  if (!format.binary)
    return decode_ascii_record(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                               format.output, format.max_station);
  return format.device == Device::Isotrak2 ? detail::decode_isotrak_binary(bytes, format)
                                           : detail::decode_fastrak_binary(bytes, format);
}

}  // namespace lumar::tracking
