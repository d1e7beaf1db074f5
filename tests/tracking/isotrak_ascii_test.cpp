// ISOTRAK II ASCII records: exact bytes, column parsing, resynchronisation, chunking.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>

#include "lumar/base/error.h"
#include "lumar/tracking/isotrak_ascii.h"
#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {
namespace {

OutputFormat list(std::vector<int> items) {
  OutputFormat f;
  f.output_list = std::move(items);
  return f;
}

ByteChunk chunk_of(const std::string& s, Nanos arrival = 0) {
  ByteChunk c;
  c.arrival = arrival;
  c.bytes.assign(s.begin(), s.end());
  return c;
}

IsotrakRecord make_record(int station, glm::dvec3 pos, glm::dvec3 att) {
  IsotrakRecord r;
  r.station = station;
  r.position = pos;
  r.attitude_deg = att;
  return r;
}

TEST(IsotrakAscii, RecordLengths) {
  EXPECT_EQ(ascii_record_length(OutputFormat{}), 47);
  EXPECT_EQ(ascii_record_length(list({2, 11, 1})), 54);
  EXPECT_EQ(ascii_record_length(list({2, 4, 11, 1})), 75);
  EXPECT_EQ(ascii_record_length(list({2, 0, 4, 1})), 48);
  EXPECT_THROW(ascii_record_length(list({2, 5, 1})), InputError);
  EXPECT_THROW(ascii_record_length(list({1, 0})), InputError);
  EXPECT_THROW(ascii_record_length(list({2, 2, 1})), InputError);
}

TEST(IsotrakAscii, EncodesDefaultListExactly) {
  const auto r = make_record(1, {12.34, -5.67, 100.0}, {-179.99, 45.5, 0.0});
  const std::string expected =
      "01 "
      "  12.34  -5.67 100.00"
      "-179.99  45.50   0.00"
      "\r\n";
  ASSERT_EQ(expected.size(), 47u);
  EXPECT_EQ(encode_ascii_record(r, OutputFormat{}), expected);
}

TEST(IsotrakAscii, EncodesQuaternionListsExactly) {
  IsotrakRecord r;
  r.station = 2;
  r.position = glm::dvec3(1.0, -999.99, 0.004);
  r.quaternion = glm::dquat(0.5, -0.5, 0.70710678, -0.00004);  // w, x, y, z
  const std::string expected_2_11_1 =
      "02 "
      "   1.00-999.99   0.00"
      " 0.5000-0.5000 0.7071 0.0000"  // -0.00004 rounds to zero: no minus sign
      "\r\n";
  ASSERT_EQ(expected_2_11_1.size(), 54u);
  EXPECT_EQ(encode_ascii_record(r, list({2, 11, 1})), expected_2_11_1);

  r.status = 'E';
  r.attitude_deg = glm::dvec3(90.0, -0.001, -0.006);
  const std::string expected_2_4_11_1 =
      "02E"
      "   1.00-999.99   0.00"
      "  90.00   0.00  -0.01"
      " 0.5000-0.5000 0.7071 0.0000"
      "\r\n";
  ASSERT_EQ(expected_2_4_11_1.size(), 75u);
  EXPECT_EQ(encode_ascii_record(r, list({2, 4, 11, 1})), expected_2_4_11_1);
}

TEST(IsotrakAscii, EncoderRefusesWhatDoesNotFit) {
  const OutputFormat f;
  EXPECT_NO_THROW(encode_ascii_record(make_record(1, {999.994, -999.994, 0}, {0, 0, 0}), f));
  EXPECT_THROW(encode_ascii_record(make_record(1, {999.995, 0, 0}, {0, 0, 0}), f), std::invalid_argument);
  EXPECT_THROW(encode_ascii_record(make_record(1, {0, -1000.0, 0}, {0, 0, 0}), f), std::invalid_argument);
  EXPECT_THROW(encode_ascii_record(make_record(1, {0, 0, NAN}, {0, 0, 0}), f), std::invalid_argument);
  EXPECT_THROW(encode_ascii_record(make_record(0, {0, 0, 0}, {0, 0, 0}), f), std::invalid_argument);
  IsotrakRecord no_attitude;
  no_attitude.position = glm::dvec3(0.0);
  EXPECT_THROW(encode_ascii_record(no_attitude, f), std::invalid_argument);
  IsotrakRecord big_q = make_record(1, {0, 0, 0}, {0, 0, 0});
  big_q.quaternion = glm::dquat(10.0, 0, 0, 0);
  EXPECT_THROW(encode_ascii_record(big_q, list({2, 11, 1})), std::invalid_argument);
}

TEST(IsotrakAscii, ParsesTouchingFieldsAndAllSignStyles) {
  const OutputFormat f = list({2, 4, 11, 1});
  const std::string bytes =
      "01 "
      "-123.45-999.99 999.99"  // touching, full width
      "+ 12.34-  1.50  +1.50"  // '+' and a sign in the first column
      "-0.9712-0.0001 0.1234-1.0000"
      "\r\n";
  const auto r = decode_ascii_record(bytes, f);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->station, 1);
  EXPECT_EQ(r->status, ' ');
  EXPECT_EQ(*r->position, glm::dvec3(-123.45, -999.99, 999.99));
  EXPECT_EQ(*r->attitude_deg, glm::dvec3(12.34, -1.5, 1.5));
  EXPECT_EQ(r->quaternion->w, -0.9712);
  EXPECT_EQ(r->quaternion->x, -0.0001);
  EXPECT_EQ(r->quaternion->y, 0.1234);
  EXPECT_EQ(r->quaternion->z, -1.0);
}

TEST(IsotrakAscii, RejectsMalformedRecordsWhole) {
  const OutputFormat f;
  const std::string good = "01   12.34  -5.67 100.00-179.99  45.50   0.00\r\n";
  ASSERT_TRUE(decode_ascii_record(good, f).has_value());
  auto with = [&](std::size_t at, const std::string& s) { return std::string(good).replace(at, s.size(), s); };
  EXPECT_FALSE(decode_ascii_record(with(1, "7"), f));        // station out of range
  EXPECT_FALSE(decode_ascii_record(with(1, "3"), f));        // ISOTRAK II has two stations
  EXPECT_TRUE(decode_ascii_record(with(1, "3"), f, 4));      // a Fastrak has four
  EXPECT_FALSE(decode_ascii_record(with(0, "1"), f));        // not a data record
  EXPECT_FALSE(decode_ascii_record(with(2, "\t"), f));       // unprintable status
  EXPECT_FALSE(decode_ascii_record(with(5, "a"), f));        // letter in a digit
  EXPECT_FALSE(decode_ascii_record(with(3, "  123.4"), f));  // point in the wrong column
  EXPECT_FALSE(decode_ascii_record(with(3, "       "), f));  // empty field
  EXPECT_FALSE(decode_ascii_record(with(3, "  - .50"), f));  // no integer digit
  EXPECT_FALSE(decode_ascii_record(with(3, " --1.50"), f));  // two signs
  EXPECT_FALSE(decode_ascii_record(with(3, " 1 2.50"), f));  // space among digits
  EXPECT_FALSE(decode_ascii_record(with(3, "1234.50"), f));  // a digit in the sign column
  EXPECT_FALSE(decode_ascii_record(with(45, "\n\r"), f));    // wrong terminator
  EXPECT_FALSE(decode_ascii_record(with(45, "  "), f));
  EXPECT_FALSE(decode_ascii_record(good.substr(0, 46), f));  // truncated
  EXPECT_TRUE(decode_ascii_record(with(2, "@"), f));         // stylus status is fine
}

TEST(IsotrakAscii, RoundTripsRandomRecords) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(-999.99, 999.99), az(-180.0, 180.0), el(-90.0, 90.0), unit(-1, 1);
  const OutputFormat f = list({2, 4, 11, 1});
  AsciiRecordParser parser(f);
  std::vector<IsotrakRecord> sent;
  for (int i = 0; i < 2000; ++i) {
    IsotrakRecord r;
    r.station = 1 + i % 2;
    r.position = glm::dvec3(pos(rng), pos(rng), pos(rng));
    r.attitude_deg = glm::dvec3(az(rng), el(rng), az(rng));
    r.quaternion = glm::normalize(glm::dquat(unit(rng), unit(rng), unit(rng), unit(rng)));
    sent.push_back(r);
    parser.push(chunk_of(encode_ascii_record(r, f)));
  }
  const auto got = parser.take_all();
  ASSERT_EQ(got.size(), sent.size());
  EXPECT_EQ(parser.skipped_bytes(), 0u);
  EXPECT_EQ(parser.rejected_records(), 0u);
  double max_pos = 0, max_att = 0, max_q = 0;
  for (std::size_t i = 0; i < sent.size(); ++i) {
    const IsotrakRecord& a = sent[i];
    const IsotrakRecord& b = got[i].record;
    EXPECT_EQ(a.station, b.station);
    for (int k = 0; k < 3; ++k) {
      max_pos = std::max(max_pos, std::abs((*a.position)[k] - (*b.position)[k]));
      max_att = std::max(max_att, std::abs((*a.attitude_deg)[k] - (*b.attitude_deg)[k]));
    }
    for (int k = 0; k < 4; ++k) max_q = std::max(max_q, std::abs((*a.quaternion)[k] - (*b.quaternion)[k]));
  }
  EXPECT_LE(max_pos, 0.005 + 1e-9);
  EXPECT_LE(max_att, 0.005 + 1e-9);
  EXPECT_LE(max_q, 0.00005 + 1e-12);
  EXPECT_GT(max_pos, 0.004);  // the random values really exercised the rounding
  std::printf("round trip: max |position error| %.6f in, |attitude error| %.6f deg, |q error| %.7f\n", max_pos, max_att,
              max_q);
}

// Records for the resynchronisation tests. None of their bytes holds "01" or "02"
// except the header, so every candidate start in the stream is one we placed.
const OutputFormat kDefault;
std::string rec(int station, double x) {
  return encode_ascii_record(make_record(station, {x, -5.67, 33.3}, {-179.99, 45.5, 3.25}), kDefault);
}

TEST(IsotrakAscii, ResynchronisesWithExactCounts) {
  const std::string r1 = rec(1, 12.34), r2 = rec(2, 56.78), r3 = rec(1, 9.87), r4 = rec(2, 43.21), r5 = rec(1, 87.65),
                    r6 = rec(2, 77.77);
  for (const auto& r : {r1, r2, r3, r4, r5, r6}) {
    ASSERT_EQ(r.find("01", 1), std::string::npos);
    ASSERT_EQ(r.find("02", 1), std::string::npos);
  }
  std::string stream;
  stream += "xyz\xff";                               // 4 garbage bytes
  stream += r1;                                      // accepted
  stream += "0900";                                  // 4 bytes: '0' + bad station, "00" is no start
  stream += r3.substr(0, 20);                        // torn record: rejected, 20 bytes skipped
  stream += r2;                                      // accepted (not lost to the torn one)
  stream += r3.substr(0, 30) + "#" + r3.substr(30);  // byte inside a record: rejected, 48 skipped
  stream += "07" + r3.substr(2);                     // station 7: 47 skipped, not a candidate
  stream += r3.substr(0, 10) + "a" + r3.substr(11);  // letter in a field: rejected, 47 skipped
  stream += r4;                                      // accepted
  stream += r5.substr(0, 45) + "  ";                 // no CR LF: rejected, 47 skipped
  stream += r6;                                      // accepted
  stream += "0";                                     // may start a record: pending
  AsciiRecordParser parser(kDefault);
  parser.push(chunk_of(stream));
  const auto got = parser.take_all();
  ASSERT_EQ(got.size(), 4u);
  EXPECT_EQ(got[0].record.position->x, 12.34);
  EXPECT_EQ(got[1].record.position->x, 56.78);
  EXPECT_EQ(got[2].record.position->x, 43.21);
  EXPECT_EQ(got[3].record.position->x, 77.77);
  EXPECT_EQ(got[1].record.station, 2);
  EXPECT_EQ(parser.accepted_records(), 4u);
  EXPECT_EQ(parser.rejected_records(), 4u);
  EXPECT_EQ(parser.skipped_bytes(), 4u + 4u + 20u + 48u + 47u + 47u + 47u);
  EXPECT_EQ(parser.pending_bytes(), 1u);
  EXPECT_EQ(4 * 47 + parser.skipped_bytes() + parser.pending_bytes(), stream.size());
}

// A stream with random garbage between records and random bytes inserted inside
// some records, as the tests below use it.
struct NoisyStream {
  std::string bytes;
  std::vector<std::size_t> good_starts;  // offsets of intact records
  std::vector<double> good_x;
};

NoisyStream make_noisy_stream(std::uint64_t seed, int n_records) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255), gap(0, 30), coin(0, 3), inside(2, 46);
  std::uniform_real_distribution<double> x(-900, 900);
  NoisyStream s;
  for (int i = 0; i < n_records; ++i) {
    for (int g = gap(rng); g > 0; --g) s.bytes += char(byte(rng));
    const double xi = std::round(x(rng) * 100) / 100;
    std::string r = encode_ascii_record(make_record(1 + i % 2, {xi, 1.5, -2.25}, {10.0, -20.0, 30.0}), kDefault);
    if (coin(rng) == 0) {
      // An extra byte at offset 2..46 shifts the CR LF out of place (at offset 1 a
      // '0' would leave an intact record behind a stray byte).
      r.insert(std::size_t(inside(rng)), 1, char(byte(rng)));
    } else {
      s.good_starts.push_back(s.bytes.size());
      s.good_x.push_back(xi);
    }
    s.bytes += r;
  }
  return s;
}

TEST(IsotrakAscii, RecoversEveryIntactRecordFromRandomGarbage) {
  const NoisyStream s = make_noisy_stream(11, 400);
  AsciiRecordParser parser(kDefault);
  parser.push(chunk_of(s.bytes));
  const auto got = parser.take_all();
  ASSERT_EQ(got.size(), s.good_x.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].record.position->x, s.good_x[i]);
  EXPECT_GT(parser.rejected_records(), 50u);  // about a quarter of 400 were torn
  EXPECT_EQ(got.size() * 47 + parser.skipped_bytes() + parser.pending_bytes(), s.bytes.size());
  std::printf("random garbage: %zu of 400 records intact and all recovered, %zu rejected, %zu bytes skipped\n",
              got.size(), parser.rejected_records(), parser.skipped_bytes());
}

TEST(IsotrakAscii, ChunkBoundariesDoNotMatterAndArrivalTimesAreExact) {
  // 100000 baud: a byte takes exactly 100 us, so expected times are exact integers.
  const int baud = 100000;
  const Nanos byte_ns = 100'000;
  ASSERT_EQ(byte_time(baud), byte_ns);
  const Nanos t0 = 5'000'000'000;  // the first byte started at t0
  const NoisyStream s = make_noisy_stream(23, 200);

  AsciiRecordParser whole(kDefault, 2, baud);
  whole.push(chunk_of(s.bytes, t0 + Nanos(s.bytes.size()) * byte_ns));
  const auto reference = whole.take_all();
  ASSERT_EQ(reference.size(), s.good_x.size());

  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> size(1, 60);
  for (int trial = 0; trial < 20; ++trial) {
    AsciiRecordParser parser(kDefault, 2, baud);
    std::vector<TimedIsotrakRecord> got;
    for (std::size_t at = 0; at < s.bytes.size();) {
      const std::size_t n = std::min<std::size_t>(std::size_t(size(rng)), s.bytes.size() - at);
      // Bytes back to back on the line: byte j (0-based in the stream) is in at t0 + (j+1) * byte.
      parser.push(chunk_of(s.bytes.substr(at, n), t0 + Nanos(at + n) * byte_ns));
      at += n;
      for (auto& r : parser.take_all()) got.push_back(r);
    }
    ASSERT_EQ(got.size(), reference.size());
    EXPECT_EQ(parser.skipped_bytes(), whole.skipped_bytes());
    EXPECT_EQ(parser.rejected_records(), whole.rejected_records());
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(*got[i].record.position, *reference[i].record.position);
      EXPECT_EQ(got[i].first_byte_arrival, t0 + Nanos(s.good_starts[i] + 1) * byte_ns) << "record " << i;
      EXPECT_EQ(reference[i].first_byte_arrival, got[i].first_byte_arrival);
    }
  }
}

TEST(IsotrakAscii, FirstByteArrivalAt115200Baud) {
  // One 47-byte chunk whose last byte arrived at 1 s: the first byte arrived
  // 46 byte times earlier, 46 * 10 / 115200 s = 3993055.6 ns -> 3993056 ns.
  AsciiRecordParser parser(kDefault, 2, 115200);
  parser.push(chunk_of(rec(1, 1.0), 1'000'000'000));
  const auto r = parser.next();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->first_byte_arrival, 996'006'944);
  EXPECT_FALSE(parser.next().has_value());
}

TEST(IsotrakAscii, ParserRefusesBadSettings) {
  EXPECT_THROW(AsciiRecordParser(kDefault, 0), InputError);
  EXPECT_THROW(AsciiRecordParser(kDefault, 2, 0), InputError);
  EXPECT_THROW(AsciiRecordParser(list({2, 16, 1})), InputError);
}

}  // namespace
}  // namespace lumar::tracking
