#include "lumar/tracking/isotrak_ascii.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "lumar/base/error.h"
#include "record_header.h"

namespace lumar::tracking {

namespace {

constexpr int kFieldWidth = 7;
using detail::is_printable;
using detail::kHeaderLength;
constexpr int kPositionDecimals = 2;    // "Sxxx.xx"
constexpr int kQuaternionDecimals = 4;  // "Sx.xxxx"

int item_length(int item) {
  switch (item) {
    case kItemSpace:
      return 1;
    case kItemCrLf:
      return 2;
    case kItemPosition:
    case kItemAttitude:
      return 3 * kFieldWidth;
    case kItemQuaternion:
      return 4 * kFieldWidth;
  }
  return 0;  // unreachable after validate_output_format
}

double decimal_scale(int decimals) { return decimals == kPositionDecimals ? 100.0 : 10000.0; }

// Right-justified like printf("%7.<decimals>f"), '-' only for values that do not
// round to zero. Seven characters hold a sign, five digits and the point.
void append_field(std::string& out, double v, int decimals, const char* what) {
  if (!std::isfinite(v)) throw std::invalid_argument(std::string("ISOTRAK ASCII encoder: ") + what + " is not finite");
  const double scaled = std::round(std::abs(v) * decimal_scale(decimals));
  if (scaled >= 100000.0)
    throw std::invalid_argument(std::string("ISOTRAK ASCII encoder: ") + what + " " + std::to_string(v) +
                                " does not fit a 7-character field");
  const long long mantissa = static_cast<long long>(scaled);
  std::string digits = std::to_string(mantissa);
  if (digits.size() < std::size_t(decimals + 1)) digits.insert(0, decimals + 1 - digits.size(), '0');
  digits.insert(digits.size() - decimals, 1, '.');
  if (v < 0 && mantissa != 0) digits.insert(0, 1, '-');
  out.append(kFieldWidth - digits.size(), ' ');
  out += digits;
}

// Reads one 7-character field. The decimal point must sit in its column; before it:
// optional spaces, an optional sign ('-', '+'), optional spaces, at least one digit.
std::optional<double> parse_field(std::string_view f, int decimals) {
  const std::size_t point = kFieldWidth - 1 - decimals;
  if (f[point] != '.') return std::nullopt;
  // Column 0 is the sign column ("Sxxx.xx"): a digit there would be a value the device
  // cannot send (>= 1000, or >= 10 for a quaternion component), i.e. misaligned bytes.
  if (f[0] >= '0' && f[0] <= '9') return std::nullopt;
  std::size_t i = 0;
  while (i < point && f[i] == ' ') ++i;
  bool negative = false;
  if (i < point && (f[i] == '-' || f[i] == '+')) {
    negative = f[i] == '-';
    ++i;
    while (i < point && f[i] == ' ') ++i;
  }
  if (i == point) return std::nullopt;  // no integer digit
  long long mantissa = 0;
  auto digit = [&](char c) {
    if (c < '0' || c > '9') return false;
    mantissa = mantissa * 10 + (c - '0');
    return true;
  };
  for (; i < point; ++i)
    if (!digit(f[i])) return std::nullopt;
  for (std::size_t j = point + 1; j < std::size_t(kFieldWidth); ++j)
    if (!digit(f[j])) return std::nullopt;
  // An exact integer divided by a power of ten: the nearest double to the decimal.
  const double v = double(mantissa) / decimal_scale(decimals);
  return negative ? -v : v;
}

template <int N>
std::optional<glm::vec<N, double>> parse_fields(std::string_view s, int decimals) {
  glm::vec<N, double> v;
  for (int k = 0; k < N; ++k) {
    const auto x = parse_field(s.substr(k * kFieldWidth, kFieldWidth), decimals);
    if (!x) return std::nullopt;
    v[k] = *x;
  }
  return v;
}

}  // namespace

int ascii_record_length(const OutputFormat& format) {
  validate_output_format(format);
  int n = kHeaderLength;
  for (int item : format.output_list) n += item_length(item);
  return n;
}

std::string encode_ascii_record(const IsotrakRecord& r, const OutputFormat& format) {
  std::string out;
  out.reserve(ascii_record_length(format));
  if (r.station < 1 || r.station > 9)
    throw std::invalid_argument("ISOTRAK ASCII encoder: station " + std::to_string(r.station) +
                                " is not a single digit 1..9");
  if (!is_printable(r.status)) throw std::invalid_argument("ISOTRAK ASCII encoder: status byte is not printable ASCII");
  out += '0';
  out += char('0' + r.station);
  out += r.status;
  auto missing = [](const char* what) {
    return std::invalid_argument(std::string("ISOTRAK ASCII encoder: the output list asks for ") + what +
                                 " but the record has none");
  };
  for (int item : format.output_list) {
    switch (item) {
      case kItemSpace:
        out += ' ';
        break;
      case kItemCrLf:
        out += "\r\n";
        break;
      case kItemPosition:
        if (!r.position) throw missing("position");
        for (int k = 0; k < 3; ++k) append_field(out, (*r.position)[k], kPositionDecimals, "position");
        break;
      case kItemAttitude:
        if (!r.attitude_deg) throw missing("attitude");
        for (int k = 0; k < 3; ++k) append_field(out, (*r.attitude_deg)[k], kPositionDecimals, "attitude");
        break;
      case kItemQuaternion: {
        if (!r.quaternion) throw missing("quaternion");
        const glm::dquat& q = *r.quaternion;
        for (double c : {q.w, q.x, q.y, q.z}) append_field(out, c, kQuaternionDecimals, "quaternion");
        break;
      }
    }
  }
  return out;
}

std::optional<IsotrakRecord> decode_ascii_record(std::string_view bytes, const OutputFormat& format, int max_station) {
  if (bytes.size() != std::size_t(ascii_record_length(format))) return std::nullopt;
  if (!detail::header_ok(bytes[0], bytes[1], bytes[2], std::clamp(max_station, 0, 9))) return std::nullopt;
  IsotrakRecord r;
  r.station = bytes[1] - '0';
  r.status = bytes[2];
  std::size_t at = kHeaderLength;
  for (int item : format.output_list) {
    const std::string_view s = bytes.substr(at, item_length(item));
    at += s.size();
    switch (item) {
      case kItemSpace:
        if (s != " ") return std::nullopt;
        break;
      case kItemCrLf:
        if (s != "\r\n") return std::nullopt;
        break;
      case kItemPosition:
        if (!(r.position = parse_fields<3>(s, kPositionDecimals))) return std::nullopt;
        break;
      case kItemAttitude:
        if (!(r.attitude_deg = parse_fields<3>(s, kPositionDecimals))) return std::nullopt;
        break;
      case kItemQuaternion: {
        const auto wxyz = parse_fields<4>(s, kQuaternionDecimals);
        if (!wxyz) return std::nullopt;
        r.quaternion = glm::dquat((*wxyz)[0], (*wxyz)[1], (*wxyz)[2], (*wxyz)[3]);
        break;
      }
    }
  }
  return r;
}

AsciiRecordParser::AsciiRecordParser(OutputFormat format, int max_station, int baud)
    : RecordParser(
          [&] {
            TrackerFormat f;
            f.output = std::move(format);
            f.max_station = max_station;
            return f;
          }(),
          baud) {}

}  // namespace lumar::tracking
