#pragma once
// One codec for every record format this code speaks: ISOTRAK II and Fastrak, ASCII
// and binary. A TrackerFormat says what the device was told to send; encode_record
// gives the exact bytes it puts on the line, decode_record reads one record back.
// The streaming side (resynchronisation, timestamps) is RecordParser
// (record_parser.h).
//
// Wire formats (header '0', station digit '1'..'9', status byte, then the output list
// items in order; see isotrak_ascii.h for the ASCII fields):
//
//   ISOTRAK II binary  payload = '0', station, status, then one little-endian int16
//       per value. Scales (TRACKER.md, VRPN): position 166.32 cm / 32767 per count,
//       the same physical length in both unit modes (so 65.48 in / 32767 after `U`,
//       exactly 166.32 / 2.54 in: a count means one length whatever the units);
//       quaternion 1 / 32767; Euler angles euler_full_scale_deg / 32767 (unverified,
//       default 180 deg). The payload is 7-bit packed: groups of 7 bytes, each group
//       (also a short last one) followed by one byte whose bit i is the top bit of the
//       group's byte i. Every wire byte has bit 7 clear except the record's first,
//       which has it set as the start mark ('0' -> 0xB0). List 2,11: 17 payload
//       bytes, 20 on the wire.
//   Fastrak binary     '0', station, status, then one little-endian IEEE-754 float32
//       per value, in device units (inches or cm, degrees).
//
// Items 0 (space) and 1 (CR LF) in binary mode: the ISOTRAK II binary record has no
// separators (its start bit frames it, and VRPN reads list 2,11 as exactly 20 bytes),
// so both items add no bytes there. The Fastrak binary record keeps them as the
// literal bytes ' ' and "\r\n" (VRPN's Fastrak reader checks for a trailing space);
// since a float32 can hold any byte, ending a Fastrak binary list with 0 or 1 is what
// makes resynchronisation there reliable.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lumar/tracking/isotrak_record.h"

namespace lumar::tracking {

enum class Device { Isotrak2, Fastrak };

// Stations the device has: 2 for an ISOTRAK II, 4 for a Fastrak.
int station_count(Device device);
// "isotrak2" / "fastrak".
std::string device_name(Device device);
// Inverse of device_name; InputError naming the accepted values otherwise.
Device parse_device(const std::string& name);
// "2,4,1" -> {2, 4, 1}. InputError for anything but comma-separated integers (the
// items themselves are checked by validate_output_format).
std::vector<int> parse_output_list(const std::string& text);

struct TrackerFormat {
  Device device = Device::Isotrak2;
  bool binary = false;                  // `f` (binary) instead of `F` (ASCII)
  OutputFormat output;                  // output list and position unit
  int max_station = 2;                  // stations accepted by the decoder: station_count(device)
  double euler_full_scale_deg = 180.0;  // ISOTRAK II binary: degrees at int16 +32767 (unverified)

  // The format with max_station set for the device.
  static TrackerFormat of(Device device, bool binary = false, OutputFormat output = {});
};

// Throws InputError for an unusable format: a bad output list, max_station outside
// 1..9, a non-positive or non-finite Euler scale.
void validate_tracker_format(const TrackerFormat& format);

// Bytes one record takes on the wire: 47 for ASCII 2,4,1; 20 for ISOTRAK II binary
// 2,11; 31 for Fastrak binary 2,11. Throws InputError for an unusable format.
int record_length(const TrackerFormat& format);

// The exact bytes the device sends for `record`. Throws std::invalid_argument when an
// item of the list has no value in the record, a value is not finite or does not fit
// (ASCII: see isotrak_ascii.h; ISOTRAK II binary: |position| > 166.32 cm, |angle| >
// the Euler full scale, |quaternion component| > 1 after rounding to counts),
// the station is outside 1..max_station, or the status byte is not printable ASCII;
// InputError for an unusable format.
std::vector<std::uint8_t> encode_record(const IsotrakRecord& record, const TrackerFormat& format);

// Whether a record of this format may start at `bytes` (needs 2 bytes): '0' (0xB0 for
// ISOTRAK II binary) followed by a station digit in 1..max_station.
bool is_record_start(std::uint8_t first, std::uint8_t second, const TrackerFormat& format);

// Decodes exactly one record (bytes.size() must equal record_length(format)).
// nullopt unless the header is right (start byte, station in 1..max_station, a
// printable status), every value is well formed (ASCII columns; ISOTRAK II binary:
// bit 7 clear on every byte after the first; Fastrak binary: finite floats within
// the range the device can report), and every separator is exact. Never returns a
// half-read record. Throws InputError for an unusable format.
std::optional<IsotrakRecord> decode_record(std::span<const std::uint8_t> bytes, const TrackerFormat& format);

}  // namespace lumar::tracking
