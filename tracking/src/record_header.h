#pragma once
// The three header bytes every record format shares: '0', station digit, status.
#include <cstdint>
#include <stdexcept>
#include <string>

namespace lumar::tracking::detail {

constexpr int kHeaderLength = 3;

inline bool is_printable(std::uint8_t c) { return c >= 0x20 && c <= 0x7e; }

// Encoder side: std::invalid_argument naming `codec` for a record that cannot be sent.
inline void check_header(int station, char status, int max_station, const char* codec) {
  if (station < 1 || station > max_station)
    throw std::invalid_argument(std::string(codec) + ": station " + std::to_string(station) + " is outside 1.." +
                                std::to_string(max_station));
  if (!is_printable(std::uint8_t(status)))
    throw std::invalid_argument(std::string(codec) + ": status byte is not printable ASCII");
}

// Decoder side: the header bytes of a (decoded) payload.
inline bool header_ok(std::uint8_t zero, std::uint8_t station, std::uint8_t status, int max_station) {
  return zero == '0' && station >= '1' && station <= '0' + max_station && is_printable(status);
}

}  // namespace lumar::tracking::detail
