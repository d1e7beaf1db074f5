#pragma once
// ISOTRAK II binary records (`f` mode): int16 values, 7-bit packed on the wire.
// Layout and scales in record_codec.h. Reached through encode_record/decode_record.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "lumar/tracking/record_codec.h"

namespace lumar::tracking::detail {

// Payload bytes -> wire bytes: groups of 7 followed by their top-bit byte, bit 7 of
// the first wire byte set as the start mark.
std::vector<std::uint8_t> pack_7bit(std::span<const std::uint8_t> payload);
// Inverse; nullopt unless the first byte has bit 7 set and no other byte has, and the
// size is a valid packed size.
std::optional<std::vector<std::uint8_t>> unpack_7bit(std::span<const std::uint8_t> wire);

int isotrak_binary_record_length(const TrackerFormat& format);
std::vector<std::uint8_t> encode_isotrak_binary(const IsotrakRecord& record, const TrackerFormat& format);
std::optional<IsotrakRecord> decode_isotrak_binary(std::span<const std::uint8_t> wire, const TrackerFormat& format);

}  // namespace lumar::tracking::detail
