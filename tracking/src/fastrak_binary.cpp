#include "fastrak_binary.h"

#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

#include "record_header.h"

namespace lumar::tracking::detail {

namespace {

// What a Fastrak can report; a float outside it is garbage, not a reading. Positions
// get the ASCII field's limit (no Fastrak reaches 10 m), angles their Euler range, and
// quaternion components 1 plus float32 rounding.
constexpr double kMaxPosition = 999.99;
constexpr double kMaxAngle = 180.0;
constexpr double kMaxQuaternion = 1.0 + 1e-6;

int item_length(int item) {
  switch (item) {
    case kItemSpace:
      return 1;
    case kItemCrLf:
      return 2;
    case kItemPosition:
    case kItemAttitude:
      return 3 * 4;
    case kItemQuaternion:
      return 4 * 4;
  }
  return 0;
}

void put_float(std::vector<std::uint8_t>& out, double value, double limit, const char* what) {
  const float f = float(value);
  if (!std::isfinite(f) || std::abs(f) > limit)
    throw std::invalid_argument(std::string("Fastrak binary encoder: ") + what + " " + std::to_string(value) +
                                " is not finite or beyond " + std::to_string(limit));
  const auto bits = std::bit_cast<std::uint32_t>(f);
  for (int i = 0; i < 4; ++i) out.push_back(std::uint8_t(bits >> (8 * i)));
}

std::optional<double> get_float(const std::uint8_t* p, double limit) {
  const std::uint32_t bits =
      std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
  const float f = std::bit_cast<float>(bits);
  if (!std::isfinite(f) || std::abs(f) > limit) return std::nullopt;
  return double(f);
}

template <int N>
std::optional<glm::vec<N, double>> get_floats(const std::uint8_t* p, double limit) {
  glm::vec<N, double> v;
  for (int k = 0; k < N; ++k) {
    const auto x = get_float(p + 4 * k, limit);
    if (!x) return std::nullopt;
    v[k] = *x;
  }
  return v;
}

}  // namespace

int fastrak_binary_record_length(const TrackerFormat& format) {
  int n = kHeaderLength;
  for (int item : format.output.output_list) n += item_length(item);
  return n;
}

std::vector<std::uint8_t> encode_fastrak_binary(const IsotrakRecord& r, const TrackerFormat& format) {
  check_header(r.station, r.status, format.max_station, "Fastrak binary encoder");
  std::vector<std::uint8_t> out{std::uint8_t('0'), std::uint8_t('0' + r.station), std::uint8_t(r.status)};
  auto missing = [](const char* what) {
    return std::invalid_argument(std::string("Fastrak binary encoder: the output list asks for ") + what +
                                 " but the record has none");
  };
  for (int item : format.output.output_list) {
    switch (item) {
      case kItemSpace:
        out.push_back(' ');
        break;
      case kItemCrLf:
        out.push_back('\r');
        out.push_back('\n');
        break;
      case kItemPosition:
        if (!r.position) throw missing("position");
        for (int k = 0; k < 3; ++k) put_float(out, (*r.position)[k], kMaxPosition, "position");
        break;
      case kItemAttitude:
        if (!r.attitude_deg) throw missing("attitude");
        for (int k = 0; k < 3; ++k) put_float(out, (*r.attitude_deg)[k], kMaxAngle, "attitude");
        break;
      case kItemQuaternion: {
        if (!r.quaternion) throw missing("quaternion");
        const glm::dquat& q = *r.quaternion;
        for (double c : {q.w, q.x, q.y, q.z}) put_float(out, c, kMaxQuaternion, "quaternion");
        break;
      }
    }
  }
  return out;
}

std::optional<IsotrakRecord> decode_fastrak_binary(std::span<const std::uint8_t> bytes, const TrackerFormat& format) {
  if (bytes.size() != std::size_t(fastrak_binary_record_length(format))) return std::nullopt;
  if (!header_ok(bytes[0], bytes[1], bytes[2], format.max_station)) return std::nullopt;
  IsotrakRecord r;
  r.station = bytes[1] - '0';
  r.status = char(bytes[2]);
  const std::uint8_t* at = bytes.data() + kHeaderLength;
  for (int item : format.output.output_list) {
    switch (item) {
      case kItemSpace:
        if (at[0] != ' ') return std::nullopt;
        break;
      case kItemCrLf:
        if (at[0] != '\r' || at[1] != '\n') return std::nullopt;
        break;
      case kItemPosition:
        if (!(r.position = get_floats<3>(at, kMaxPosition))) return std::nullopt;
        break;
      case kItemAttitude:
        if (!(r.attitude_deg = get_floats<3>(at, kMaxAngle))) return std::nullopt;
        break;
      case kItemQuaternion: {
        const auto wxyz = get_floats<4>(at, kMaxQuaternion);
        if (!wxyz) return std::nullopt;
        r.quaternion = glm::dquat((*wxyz)[0], (*wxyz)[1], (*wxyz)[2], (*wxyz)[3]);
        break;
      }
    }
    at += item_length(item);
  }
  return r;
}

}  // namespace lumar::tracking::detail
