#pragma once
// ISOTRAK II / Fastrak ASCII data records (`F` mode; both devices use the same
// layout): encoder and single-record decoder. The unified codec (record_codec.h) and
// parser (record_parser.h) dispatch here for ASCII formats.
//
// Layout: '0', station digit, status byte, then the output list items in order:
//   0  -> ' '                    1  -> "\r\n"
//   2  -> 3 x "Sxxx.xx" (7 chars, 2 decimals)  position in device units
//   4  -> 3 x "Sxxx.xx"          azimuth, elevation, roll in degrees
//   11 -> 4 x "Sx.xxxx" (7 chars, 4 decimals)  quaternion, w first
// Fields are fixed width and may touch ("  13.98-0.9712"), so they are read by
// column. The encoder writes numbers right-justified like printf("%7.2f")
// ("  -1.50", "  12.34"); the decoder also accepts a '+' sign and a sign in the
// first column ("-  1.50"), but insists on the decimal point's column, on the first
// column being a sign or a space (never a digit: "1000.00" is not a field), and on every
// other character being a digit.
#include <optional>
#include <string>
#include <string_view>

#include "lumar/tracking/isotrak_record.h"
#include "lumar/tracking/record_parser.h"

namespace lumar::tracking {

// Bytes in one ASCII record for this format (47 for the default 2,4,1).
// Throws InputError for an unsupported format.
int ascii_record_length(const OutputFormat& format);

// The exact bytes the device sends for `record`. Throws std::invalid_argument when
// an item of the list has no value in the record, a value is not finite or does
// not fit its 7-character field (|v| >= 999.995 for 2/4, >= 9.99995 for 11), or the
// station is not a single digit 1..9, or the status byte is not printable ASCII;
// InputError for an unsupported format.
std::string encode_ascii_record(const IsotrakRecord& record, const OutputFormat& format);

// Decodes exactly one record (bytes.size() must equal ascii_record_length()).
// nullopt unless the header is '0' + station in 1..max_station + a printable status,
// every numeric field is well formed, every space item is ' ' and every CR LF item
// is "\r\n". Never returns a half-read record. max_station is capped at 9.
// Throws InputError for an unsupported format.
std::optional<IsotrakRecord> decode_ascii_record(std::string_view bytes, const OutputFormat& format,
                                                 int max_station = 2);

// Streaming parser for ASCII records: the RecordParser (record_parser.h, which
// documents resynchronisation, counters and timestamps) with an ASCII format.
class AsciiRecordParser : public RecordParser {
 public:
  // Throws InputError for an unsupported format, a baud <= 0 or max_station outside 1..9.
  explicit AsciiRecordParser(OutputFormat format, int max_station = 2, int baud = 115200);
};

}  // namespace lumar::tracking
