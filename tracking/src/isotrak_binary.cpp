#include "isotrak_binary.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "record_header.h"

namespace lumar::tracking::detail {

namespace {

constexpr double kFullScaleCount = 32767.0;
constexpr double kPositionFullScaleCm = 166.32;  // VRPN: 1.6632 m / 32767 per count
constexpr double kCentimetresPerInch = 2.54;
constexpr int kGroup = 7;

int payload_length(const OutputFormat& output) {
  int n = kHeaderLength;
  for (int item : output.output_list) {
    if (item == kItemPosition || item == kItemAttitude) n += 3 * 2;
    if (item == kItemQuaternion) n += 4 * 2;
  }
  return n;
}

int packed_length(int payload) { return payload + (payload + kGroup - 1) / kGroup; }

// Device units per count for each item.
double position_step(const TrackerFormat& f) {
  const double full = f.output.centimetres ? kPositionFullScaleCm : kPositionFullScaleCm / kCentimetresPerInch;
  return full / kFullScaleCount;
}
double attitude_step(const TrackerFormat& f) { return f.euler_full_scale_deg / kFullScaleCount; }
constexpr double kQuaternionStep = 1.0 / kFullScaleCount;

void put_count(std::vector<std::uint8_t>& out, double value, double step, const char* what) {
  if (!std::isfinite(value))
    throw std::invalid_argument(std::string("ISOTRAK II binary encoder: ") + what + " is not finite");
  const double count = std::round(value / step);
  if (std::abs(count) > kFullScaleCount)
    throw std::invalid_argument(std::string("ISOTRAK II binary encoder: ") + what + " " + std::to_string(value) +
                                " is beyond the int16 full scale");
  const auto bits = std::uint16_t(std::int16_t(count));
  out.push_back(std::uint8_t(bits & 0xFF));
  out.push_back(std::uint8_t(bits >> 8));
}

double get_count(const std::uint8_t* p, double step) {
  return double(std::int16_t(std::uint16_t(p[0] | (p[1] << 8)))) * step;
}

}  // namespace

std::vector<std::uint8_t> pack_7bit(std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> wire;
  wire.reserve(packed_length(int(payload.size())));
  for (std::size_t g = 0; g < payload.size(); g += kGroup) {
    std::uint8_t high = 0;
    for (std::size_t i = 0; i < kGroup && g + i < payload.size(); ++i) {
      wire.push_back(payload[g + i] & 0x7F);
      high |= std::uint8_t((payload[g + i] >> 7) << i);
    }
    wire.push_back(high);
  }
  if (!wire.empty()) wire[0] |= 0x80;
  return wire;
}

std::optional<std::vector<std::uint8_t>> unpack_7bit(std::span<const std::uint8_t> wire) {
  if (wire.empty() || !(wire[0] & 0x80)) return std::nullopt;
  for (std::size_t i = 1; i < wire.size(); ++i)
    if (wire[i] & 0x80) return std::nullopt;
  // A group of k bytes takes k + 1 on the wire; a lone top-bit byte is not a group.
  if (wire.size() % (kGroup + 1) == 1) return std::nullopt;
  std::vector<std::uint8_t> payload;
  payload.reserve(wire.size());
  for (std::size_t g = 0; g < wire.size(); g += kGroup + 1) {
    const std::size_t k = std::min<std::size_t>(kGroup, wire.size() - g - 1);
    const std::uint8_t high = wire[g + k];
    if (high >> k) return std::nullopt;  // top bits for bytes the group does not have
    for (std::size_t i = 0; i < k; ++i)
      payload.push_back(std::uint8_t((wire[g + i] & 0x7F) | (((high >> i) & 1) << 7)));
  }
  return payload;
}

int isotrak_binary_record_length(const TrackerFormat& format) { return packed_length(payload_length(format.output)); }

std::vector<std::uint8_t> encode_isotrak_binary(const IsotrakRecord& r, const TrackerFormat& format) {
  check_header(r.station, r.status, format.max_station, "ISOTRAK II binary encoder");
  std::vector<std::uint8_t> payload{std::uint8_t('0'), std::uint8_t('0' + r.station), std::uint8_t(r.status)};
  auto missing = [](const char* what) {
    return std::invalid_argument(std::string("ISOTRAK II binary encoder: the output list asks for ") + what +
                                 " but the record has none");
  };
  for (int item : format.output.output_list) {
    switch (item) {
      case kItemPosition:
        if (!r.position) throw missing("position");
        for (int k = 0; k < 3; ++k) put_count(payload, (*r.position)[k], position_step(format), "position");
        break;
      case kItemAttitude:
        if (!r.attitude_deg) throw missing("attitude");
        for (int k = 0; k < 3; ++k) put_count(payload, (*r.attitude_deg)[k], attitude_step(format), "attitude");
        break;
      case kItemQuaternion: {
        if (!r.quaternion) throw missing("quaternion");
        const glm::dquat& q = *r.quaternion;
        for (double c : {q.w, q.x, q.y, q.z}) put_count(payload, c, kQuaternionStep, "quaternion");
        break;
      }
      default:
        break;  // space and CR LF: no bytes in a binary record
    }
  }
  return pack_7bit(payload);
}

std::optional<IsotrakRecord> decode_isotrak_binary(std::span<const std::uint8_t> wire, const TrackerFormat& format) {
  if (wire.size() != std::size_t(isotrak_binary_record_length(format))) return std::nullopt;
  const auto payload = unpack_7bit(wire);
  if (!payload) return std::nullopt;
  const std::vector<std::uint8_t>& p = *payload;
  if (!header_ok(p[0], p[1], p[2], format.max_station)) return std::nullopt;
  IsotrakRecord r;
  r.station = p[1] - '0';
  r.status = char(p[2]);
  const std::uint8_t* at = p.data() + kHeaderLength;
  for (int item : format.output.output_list) {
    switch (item) {
      case kItemPosition: {
        const double s = position_step(format);
        r.position = glm::dvec3(get_count(at, s), get_count(at + 2, s), get_count(at + 4, s));
        at += 6;
        break;
      }
      case kItemAttitude: {
        const double s = attitude_step(format);
        r.attitude_deg = glm::dvec3(get_count(at, s), get_count(at + 2, s), get_count(at + 4, s));
        at += 6;
        break;
      }
      case kItemQuaternion: {
        const double s = kQuaternionStep;
        r.quaternion = glm::dquat(get_count(at, s), get_count(at + 2, s), get_count(at + 4, s), get_count(at + 6, s));
        at += 8;
        break;
      }
      default:
        break;
    }
  }
  return r;
}

}  // namespace lumar::tracking::detail
