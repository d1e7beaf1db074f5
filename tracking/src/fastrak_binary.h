#pragma once
// Fastrak binary records (`f` mode): little-endian IEEE-754 float32 values.
// Layout in record_codec.h. Reached through encode_record/decode_record.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "lumar/tracking/record_codec.h"

namespace lumar::tracking::detail {

int fastrak_binary_record_length(const TrackerFormat& format);
std::vector<std::uint8_t> encode_fastrak_binary(const IsotrakRecord& record, const TrackerFormat& format);
std::optional<IsotrakRecord> decode_fastrak_binary(std::span<const std::uint8_t> bytes, const TrackerFormat& format);

}  // namespace lumar::tracking::detail
