// The unified record codec and parser: ISOTRAK II and Fastrak, ASCII and binary.
// Exact wire bytes against hand-computed sequences, round trips within each format's
// quantisation, and recovery from 1 % of bytes replaced by garbage with exact counts.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "lumar/base/error.h"
#include "lumar/tracking/pose_conversion.h"
#include "lumar/tracking/record_codec.h"
#include "lumar/tracking/record_parser.h"
#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {
namespace {

using Bytes = std::vector<std::uint8_t>;

OutputFormat list(std::vector<int> items, bool cm = false) {
  OutputFormat f;
  f.output_list = std::move(items);
  f.centimetres = cm;
  return f;
}

ByteChunk chunk_of(const Bytes& b, std::size_t from, std::size_t n, Nanos arrival) {
  ByteChunk c;
  c.arrival = arrival;
  c.bytes.assign(b.begin() + std::ptrdiff_t(from), b.begin() + std::ptrdiff_t(from + n));
  return c;
}

constexpr double kCountCm = 166.32 / 32767.0;  // ISOTRAK II binary position step (cm)

TEST(RecordCodec, RecordLengths) {
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Isotrak2)), 47);
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Fastrak, false, list({2, 11, 1}))), 54);
  // ISOTRAK II binary: 3 + 2 per value payload bytes, plus one top-bit byte per 7.
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Isotrak2, true, list({2, 11}))), 20);     // 17 + 3
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Isotrak2, true, list({2, 4}))), 18);      // 15 + 3
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Isotrak2, true, list({2, 4, 11}))), 27);  // 23 + 4
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Isotrak2, true, list({2, 11, 1}))), 20);  // no separators
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Isotrak2, true, list({0, 2, 11, 1}))), 20);
  // Fastrak binary: 3 + 4 per value, separators kept as bytes.
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Fastrak, true, list({2, 11}))), 31);
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Fastrak, true, list({2, 4}))), 27);
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Fastrak, true, list({2, 11, 0}))), 32);
  EXPECT_EQ(record_length(TrackerFormat::of(Device::Fastrak, true, list({2, 4, 1}))), 29);
  EXPECT_THROW(record_length(TrackerFormat::of(Device::Fastrak, true, list({2, 5}))), InputError);
  TrackerFormat bad = TrackerFormat::of(Device::Isotrak2);
  bad.max_station = 10;
  EXPECT_THROW(record_length(bad), InputError);
  EXPECT_EQ(TrackerFormat::of(Device::Fastrak).max_station, 4);
  EXPECT_EQ(TrackerFormat::of(Device::Isotrak2).max_station, 2);
}

TEST(RecordCodec, ParsesDeviceNamesAndLists) {
  EXPECT_EQ(parse_device("isotrak2"), Device::Isotrak2);
  EXPECT_EQ(parse_device("fastrak"), Device::Fastrak);
  EXPECT_THROW(parse_device("liberty"), InputError);
  EXPECT_EQ(parse_output_list("2,4,1"), (std::vector<int>{2, 4, 1}));
  EXPECT_EQ(parse_output_list("11"), (std::vector<int>{11}));
  for (const char* bad : {"", "2,,1", "2,4,", "a", "2;4", "-2", "2, 4", "1234"})
    EXPECT_THROW(parse_output_list(bad), InputError) << bad;
}

// Record for list 2,11 in centimetres, with integer counts chosen so the packed bytes
// can be worked out by hand (values from counts, so rounding is exact).
IsotrakRecord hand_record() {
  IsotrakRecord r;
  r.station = 1;
  r.status = ' ';
  r.position = glm::dvec3(1000 * kCountCm, -1 * kCountCm, 200 * kCountCm);
  r.quaternion = glm::dquat(28378 / 32767.0, -16384 / 32767.0, 0.0, 128 / 32767.0);  // ~(cos 30, -sin 30, 0, 0)
  return r;
}

TEST(RecordCodec, IsotrakBinaryPackingMatchesHandComputedBytes) {
  // Payload (17 bytes): '0' '1' ' ' | x=1000 E8 03 | y=-1 FF FF | z=200 C8 00 |
  //   w=28378 DA 6E | qx=-16384 00 C0 | qy=0 00 00 | qz=128 80 00
  // Group 0: 30 31 20 E8 03 FF FF -> low 7 bits 30 31 20 68 03 7F 7F, top bits of
  //   bytes 3, 5, 6 -> 0b0110'1000 = 0x68; first byte gets the start mark: B0.
  // Group 1: C8 00 DA 6E 00 C0 00 -> 48 00 5A 6E 00 40 00, top bits of bytes 0, 2, 5
  //   -> 0b0010'0101 = 0x25.
  // Group 2: 00 80 00 -> 00 00 00, top bit of byte 1 -> 0x02.
  const Bytes expected = {0xB0, 0x31, 0x20, 0x68, 0x03, 0x7F, 0x7F, 0x68,  //
                          0x48, 0x00, 0x5A, 0x6E, 0x00, 0x40, 0x00, 0x25,  //
                          0x00, 0x00, 0x00, 0x02};
  const TrackerFormat f = TrackerFormat::of(Device::Isotrak2, true, list({2, 11}, true));
  EXPECT_EQ(encode_record(hand_record(), f), expected);
  // CR LF and space add nothing to a binary ISOTRAK II record.
  EXPECT_EQ(encode_record(hand_record(), TrackerFormat::of(Device::Isotrak2, true, list({0, 2, 11, 1}, true))),
            expected);

  const auto back = decode_record(expected, f);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->station, 1);
  EXPECT_EQ(back->status, ' ');
  EXPECT_DOUBLE_EQ(back->position->x, 1000 * kCountCm);
  EXPECT_DOUBLE_EQ(back->position->y, -kCountCm);
  EXPECT_DOUBLE_EQ(back->position->z, 200 * kCountCm);
  EXPECT_DOUBLE_EQ(back->quaternion->w, 28378 / 32767.0);
  EXPECT_DOUBLE_EQ(back->quaternion->x, -16384 / 32767.0);
  EXPECT_DOUBLE_EQ(back->quaternion->y, 0.0);
  EXPECT_DOUBLE_EQ(back->quaternion->z, 128 / 32767.0);

  // The same counts in inches mode mean the same lengths: 65.48 in full scale.
  const TrackerFormat inches = TrackerFormat::of(Device::Isotrak2, true, list({2, 11}, false));
  const auto in = decode_record(expected, inches);
  ASSERT_TRUE(in.has_value());
  EXPECT_NEAR(in->position->x, 1000 * kCountCm / 2.54, 1e-12);
  EXPECT_NEAR(in->position->x * kMetresPerInch, back->position->x * kMetresPerCentimetre, 1e-15);
}

TEST(RecordCodec, IsotrakBinaryRejectsBrokenFraming) {
  const TrackerFormat f = TrackerFormat::of(Device::Isotrak2, true, list({2, 11}, true));
  const Bytes good = encode_record(hand_record(), f);
  ASSERT_TRUE(decode_record(good, f));
  auto with = [&](std::size_t at, std::uint8_t v) {
    Bytes b = good;
    b[at] = v;
    return b;
  };
  EXPECT_FALSE(decode_record(with(0, 0x30), f));                        // no start mark
  EXPECT_FALSE(decode_record(with(5, 0xFF), f));                        // bit 7 inside the record
  EXPECT_FALSE(decode_record(with(1, 0x33), f));                        // station 3 on an ISOTRAK II
  EXPECT_FALSE(decode_record(with(2, 0x09), f));                        // unprintable status
  EXPECT_FALSE(decode_record(with(7, 0x69), f));                        // top bit for '0' makes it 0xB0
  EXPECT_FALSE(decode_record(with(19, 0x0A), f));                       // top bit for a byte the short group lacks
  EXPECT_FALSE(decode_record(Bytes(good.begin(), good.end() - 1), f));  // truncated
  EXPECT_TRUE(decode_record(with(4, 0x05), f));                         // a changed value is still a record
}

TEST(RecordCodec, FastrakBinaryMatchesHandComputedBytes) {
  // float32 little-endian: 1.0 = 3F800000, -2.5 = C0200000, 0.5 = 3F000000, 0 = 0.
  IsotrakRecord r;
  r.station = 4;
  r.status = 'E';
  r.position = glm::dvec3(1.0, -2.5, 0.0);
  r.quaternion = glm::dquat(1.0, 0.0, -0.5, 0.5);
  const Bytes expected = {'0',  '4',  'E',                                             //
                          0x00, 0x00, 0x80, 0x3F, 0x00, 0x00, 0x20, 0xC0, 0, 0, 0, 0,  //
                          0x00, 0x00, 0x80, 0x3F, 0,    0,    0,    0,                 //
                          0x00, 0x00, 0x00, 0xBF, 0x00, 0x00, 0x00, 0x3F,              //
                          ' '};
  const TrackerFormat f = TrackerFormat::of(Device::Fastrak, true, list({2, 11, 0}));
  EXPECT_EQ(encode_record(r, f), expected);
  const auto back = decode_record(expected, f);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->station, 4);
  EXPECT_EQ(back->status, 'E');
  EXPECT_EQ(*back->position, glm::dvec3(1.0, -2.5, 0.0));
  EXPECT_EQ(back->quaternion->y, -0.5);

  auto with = [&](std::size_t at, std::uint8_t v) {
    Bytes b = expected;
    b[at] = v;
    return b;
  };
  EXPECT_FALSE(decode_record(with(31, 'x'), f));   // separator must be ' '
  EXPECT_FALSE(decode_record(with(1, '5'), f));    // a Fastrak has four stations
  EXPECT_FALSE(decode_record(with(6, 0xFF), f));   // 1.0 -> NaN (exponent all ones)
  EXPECT_FALSE(decode_record(with(18, 0x40), f));  // w = 2.0: no unit quaternion
  EXPECT_FALSE(decode_record(with(6, 0x4F), f));   // x = 4.3e9: beyond any Fastrak
  EXPECT_TRUE(decode_record(with(4, 0x01), f));    // a changed mantissa is still a record
}

TEST(RecordCodec, EncoderRefusesWhatDoesNotFit) {
  const TrackerFormat ib = TrackerFormat::of(Device::Isotrak2, true, list({2, 4}, true));
  IsotrakRecord r;
  r.position = glm::dvec3(166.32, -166.32, 0.0);
  r.attitude_deg = glm::dvec3(180.0, -90.0, -180.0);
  EXPECT_NO_THROW(encode_record(r, ib));
  r.position->x = 166.33;
  EXPECT_THROW(encode_record(r, ib), std::invalid_argument);
  r.position->x = 0;
  r.attitude_deg->z = 180.01;
  EXPECT_THROW(encode_record(r, ib), std::invalid_argument);
  r.attitude_deg->z = 0;
  r.station = 3;
  EXPECT_THROW(encode_record(r, ib), std::invalid_argument);              // ISOTRAK II: 2 stations
  EXPECT_NO_THROW(encode_record(r, TrackerFormat::of(Device::Fastrak)));  // Fastrak: 4
  r.station = 5;
  EXPECT_THROW(encode_record(r, TrackerFormat::of(Device::Fastrak)), std::invalid_argument);
  EXPECT_THROW(encode_record(r, TrackerFormat::of(Device::Fastrak, true, list({2, 4}))), std::invalid_argument);
  r.station = 1;
  r.position->y = NAN;
  EXPECT_THROW(encode_record(r, TrackerFormat::of(Device::Fastrak, true, list({2, 4}))), std::invalid_argument);
  IsotrakRecord no_q;
  no_q.position = glm::dvec3(0.0);
  EXPECT_THROW(encode_record(no_q, TrackerFormat::of(Device::Isotrak2, true, list({2, 11}))), std::invalid_argument);
  EXPECT_THROW(encode_record(no_q, TrackerFormat::of(Device::Fastrak, true, list({2, 11}))), std::invalid_argument);
}

// ---------------------------------------------------------------------------------
// Round trips: every format, both units, the lists a driver would use.

struct Quantisation {
  double position, attitude, quaternion;  // largest possible decode error (device units, deg)
};

Quantisation quantisation(const TrackerFormat& f) {
  if (!f.binary) return {0.005, 0.005, 0.00005};
  if (f.device == Device::Isotrak2) {
    const double full = f.output.centimetres ? 166.32 : 166.32 / 2.54;
    return {0.5 * full / 32767, 0.5 * 180.0 / 32767, 0.5 / 32767};
  }
  // float32 with a 24-bit significand: half an ulp in the top binade of each range
  // (positions < 1024, angles < 256, quaternion components < 1).
  return {std::ldexp(1.0, 10 - 25), std::ldexp(1.0, 8 - 25), std::ldexp(1.0, -25)};
}

double max_position(const TrackerFormat& f) {
  if (f.binary && f.device == Device::Isotrak2) return f.output.centimetres ? 166.0 : 65.0;
  return 999.0;
}

class RoundTrip : public ::testing::TestWithParam<std::tuple<Device, bool, bool, std::vector<int>>> {};

TEST_P(RoundTrip, DecodesWithinQuantisation) {
  const auto& [device, binary, cm, items] = GetParam();
  const TrackerFormat f = TrackerFormat::of(device, binary, list(items, cm));
  const int length = record_length(f);
  const double pmax = max_position(f);
  const Quantisation q = quantisation(f);
  std::mt19937_64 rng(17 + length);
  std::uniform_real_distribution<double> pos(-pmax, pmax), az(-180.0, 180.0), el(-90.0, 90.0), unit(-1, 1);

  // Bytes back to back at 1 Mbaud (10 us each): record k's first byte is in at
  // (k * length + 1) * 10 us.
  const int baud = 1'000'000;
  const Nanos byte_ns = 10'000;
  std::vector<IsotrakRecord> sent;
  Bytes stream;
  for (int i = 0; i < 1500; ++i) {
    IsotrakRecord r;
    r.station = 1 + i % f.max_station;
    r.status = i % 7 == 0 ? 'B' : ' ';
    r.position = glm::dvec3(pos(rng), pos(rng), pos(rng));
    r.attitude_deg = glm::dvec3(az(rng), el(rng), az(rng));
    r.quaternion = glm::normalize(glm::dquat(unit(rng), unit(rng), unit(rng), unit(rng)));
    const Bytes b = encode_record(r, f);
    ASSERT_EQ(int(b.size()), length);
    stream.insert(stream.end(), b.begin(), b.end());
    sent.push_back(r);
  }
  RecordParser parser(f, baud);
  std::uniform_int_distribution<int> size(1, 3 * length);
  std::vector<TimedIsotrakRecord> got;
  for (std::size_t at = 0; at < stream.size();) {
    const std::size_t n = std::min<std::size_t>(std::size_t(size(rng)), stream.size() - at);
    parser.push(chunk_of(stream, at, n, Nanos(at + n) * byte_ns));
    at += n;
    for (auto& r : parser.take_all()) got.push_back(std::move(r));
  }
  ASSERT_EQ(got.size(), sent.size());
  EXPECT_EQ(parser.skipped_bytes(), 0u);
  EXPECT_EQ(parser.rejected_records(), 0u);
  EXPECT_EQ(parser.pending_bytes(), 0u);

  double e_pos = 0, e_att = 0, e_q = 0, e_metres = 0;
  const bool has_att = std::find(items.begin(), items.end(), 4) != items.end();
  const bool has_q = std::find(items.begin(), items.end(), 11) != items.end();
  for (std::size_t i = 0; i < sent.size(); ++i) {
    const IsotrakRecord& a = sent[i];
    const IsotrakRecord& b = got[i].record;
    ASSERT_EQ(b.station, a.station);
    ASSERT_EQ(b.status, a.status);
    ASSERT_EQ(got[i].first_byte_arrival, Nanos(i * length + 1) * byte_ns);
    ASSERT_EQ(b.attitude_deg.has_value(), has_att);
    ASSERT_EQ(b.quaternion.has_value(), has_q);
    for (int k = 0; k < 3; ++k) e_pos = std::max(e_pos, std::abs((*a.position)[k] - (*b.position)[k]));
    if (has_att)
      for (int k = 0; k < 3; ++k) e_att = std::max(e_att, std::abs((*a.attitude_deg)[k] - (*b.attitude_deg)[k]));
    if (has_q)
      for (int k = 0; k < 4; ++k) e_q = std::max(e_q, std::abs((*a.quaternion)[k] - (*b.quaternion)[k]));
    // And through the edge of tracking/: metres.
    const auto sample = to_pose_sample(b, f.output, 0);
    ASSERT_TRUE(sample.has_value());
    const glm::dvec3 truth_m = *a.position * metres_per_device_unit(f.output);
    e_metres = std::max(e_metres, glm::length(sample->T_transmitter_sensor.translation - truth_m));
  }
  EXPECT_LE(e_pos, q.position * (1 + 1e-9));
  EXPECT_LE(e_att, q.attitude * (1 + 1e-9));
  EXPECT_LE(e_q, q.quaternion * (1 + 1e-9));
  EXPECT_LE(e_metres, std::sqrt(3.0) * q.position * metres_per_device_unit(f.output) * (1 + 1e-9));
  // The values really exercised the rounding (not a format that is trivially exact).
  EXPECT_GT(e_pos, 0.5 * q.position);
  if (has_att) {
    EXPECT_GT(e_att, 0.5 * q.attitude);
  }
  if (has_q) {
    EXPECT_GT(e_q, 0.5 * q.quaternion);
  }
  std::printf("%s %s %s list", device_name(device).c_str(), binary ? "binary" : "ascii", cm ? "cm" : "in");
  for (int item : items) std::printf(" %d", item);
  std::printf(": %d bytes, max error position %.3g, attitude %.3g deg, quaternion %.3g\n", length, e_pos, e_att, e_q);
}

std::vector<std::tuple<Device, bool, bool, std::vector<int>>> round_trip_cases() {
  std::vector<std::tuple<Device, bool, bool, std::vector<int>>> cases;
  for (Device d : {Device::Isotrak2, Device::Fastrak})
    for (bool cm : {false, true}) {
      for (auto l : {std::vector<int>{2, 4, 1}, std::vector<int>{2, 11, 1}, std::vector<int>{2, 4, 11, 1}})
        cases.emplace_back(d, false, cm, l);
      for (auto l : {std::vector<int>{2, 4}, std::vector<int>{2, 11}, std::vector<int>{2, 4, 11, 1}})
        cases.emplace_back(d, true, cm, l);
    }
  return cases;
}

std::string case_name(const ::testing::TestParamInfo<RoundTrip::ParamType>& info) {
  const auto& [device, binary, cm, items] = info.param;
  std::string s = device_name(device) + (binary ? "_binary_" : "_ascii_") + (cm ? "cm" : "in") + "_list";
  for (int item : items) s += "_" + std::to_string(item);
  return s;
}

INSTANTIATE_TEST_SUITE_P(AllFormats, RoundTrip, ::testing::ValuesIn(round_trip_cases()), case_name);

// ---------------------------------------------------------------------------------
// 1 % of the bytes replaced by garbage.

class Garbage : public ::testing::TestWithParam<std::tuple<Device, bool, std::vector<int>>> {};

TEST_P(Garbage, EveryUntouchedRecordIsRecoveredWithExactCounts) {
  const auto& [device, binary, items] = GetParam();
  const TrackerFormat f = TrackerFormat::of(device, binary, list(items, true));
  const std::size_t L = std::size_t(record_length(f));
  const int n_records = 3000;
  std::mt19937_64 rng(99 + L);
  std::uniform_real_distribution<double> pos(-100, 100), az(-180.0, 180.0), el(-90.0, 90.0), unit(-1, 1);
  Bytes clean;
  for (int i = 0; i < n_records; ++i) {
    IsotrakRecord r;
    r.station = 1 + i % f.max_station;
    r.position = glm::dvec3(pos(rng), pos(rng), pos(rng));
    r.attitude_deg = glm::dvec3(az(rng), el(rng), az(rng));
    r.quaternion = glm::normalize(glm::dquat(unit(rng), unit(rng), unit(rng), unit(rng)));
    const Bytes b = encode_record(r, f);
    clean.insert(clean.end(), b.begin(), b.end());
  }
  // Each byte is replaced with probability 1 %, by a different random byte.
  Bytes noisy = clean;
  std::bernoulli_distribution hit(0.01);
  std::uniform_int_distribution<int> delta(1, 255);
  std::vector<bool> touched(n_records, false);
  std::size_t replaced = 0;
  for (std::size_t i = 0; i < noisy.size(); ++i)
    if (hit(rng)) {
      noisy[i] = std::uint8_t(noisy[i] + delta(rng));
      touched[i / L] = true;
      ++replaced;
    }

  // What must come out: every untouched record, plus any touched one whose garbage
  // happens to leave a valid record (a digit replaced by a digit, say).
  std::vector<bool> expect_accept(n_records);
  std::size_t untouched = 0, touched_but_valid = 0;
  for (int k = 0; k < n_records; ++k) {
    if (!touched[k]) {
      expect_accept[k] = true;
      ++untouched;
      continue;
    }
    expect_accept[k] = decode_record(std::span(noisy).subspan(k * L, L), f).has_value();
    touched_but_valid += expect_accept[k];
  }
  // Rejections: the hunt visits every byte outside accepted records; each candidate
  // start there ('0' or 0xB0, then a station digit) with a whole record after it is
  // one rejected record.
  const std::uint8_t start = binary && device == Device::Isotrak2 ? 0xB0 : '0';
  std::size_t expect_rejected = 0, expect_pending = 0;
  for (std::size_t p = 0; p < noisy.size();) {
    if (p % L == 0 && expect_accept[p / L]) {
      p += L;
      continue;
    }
    const bool candidate_start = noisy[p] == start;
    if (candidate_start && p + 1 == noisy.size()) {
      expect_pending = 1;
      break;
    }
    const bool candidate = candidate_start && noisy[p + 1] >= '1' && noisy[p + 1] <= '0' + f.max_station;
    if (candidate && p + L > noisy.size()) {
      expect_pending = noisy.size() - p;
      break;
    }
    expect_rejected += candidate;
    ++p;
  }

  // Arrival times tell which record each output came from: byte j is in at (j+1) us.
  const int baud = 10'000'000;
  ASSERT_EQ(byte_time(baud), 1000);
  RecordParser parser(f, baud);
  std::uniform_int_distribution<int> size(1, 100);
  std::vector<TimedIsotrakRecord> got;
  for (std::size_t at = 0; at < noisy.size();) {
    const std::size_t n = std::min<std::size_t>(std::size_t(size(rng)), noisy.size() - at);
    parser.push(chunk_of(noisy, at, n, Nanos(at + n) * 1000));
    at += n;
    for (auto& r : parser.take_all()) got.push_back(std::move(r));
  }

  std::size_t next = 0;
  for (const auto& r : got) {
    const Nanos offset = r.first_byte_arrival / 1000 - 1;
    ASSERT_EQ(offset % Nanos(L), 0) << "a record was read out of alignment at byte " << offset;
    const std::size_t k = std::size_t(offset) / L;
    ASSERT_TRUE(expect_accept[k]) << "record " << k << " should not have decoded";
    while (next < k) ASSERT_FALSE(expect_accept[next++]) << "record " << next - 1 << " was lost";
    ++next;
    const auto reference = decode_record(std::span(clean).subspan(k * L, L), f);
    if (!touched[k]) {
      ASSERT_TRUE(reference.has_value());
      ASSERT_EQ(r.record.station, reference->station);
      ASSERT_EQ(*r.record.position, *reference->position);
    }
  }
  while (next < std::size_t(n_records)) ASSERT_FALSE(expect_accept[next++]) << "record " << next - 1 << " was lost";

  EXPECT_EQ(parser.accepted_records(), untouched + touched_but_valid);
  EXPECT_EQ(parser.rejected_records(), expect_rejected);
  EXPECT_EQ(parser.pending_bytes(), expect_pending);
  EXPECT_EQ(parser.skipped_bytes(), noisy.size() - parser.accepted_records() * L - expect_pending);
  EXPECT_GT(untouched, std::size_t(n_records) / 2);
  EXPECT_LT(untouched, std::size_t(n_records));
  std::printf(
      "%s %s, %zu-byte records: %zu bytes replaced, %zu of %d records untouched (all recovered), "
      "%zu touched but still valid, %zu rejected, %zu bytes skipped\n",
      device_name(device).c_str(), binary ? "binary" : "ascii", L, replaced, untouched, n_records, touched_but_valid,
      parser.rejected_records(), parser.skipped_bytes());
}

std::string garbage_case_name(const ::testing::TestParamInfo<Garbage::ParamType>& info) {
  const auto& [device, binary, items] = info.param;
  std::string s = device_name(device) + (binary ? "_binary_list" : "_ascii_list");
  for (int item : items) s += "_" + std::to_string(item);
  return s;
}

INSTANTIATE_TEST_SUITE_P(AllFormats, Garbage,
                         ::testing::Values(std::make_tuple(Device::Isotrak2, false, std::vector<int>{2, 4, 1}),
                                           std::make_tuple(Device::Isotrak2, false, std::vector<int>{2, 11, 1}),
                                           std::make_tuple(Device::Isotrak2, true, std::vector<int>{2, 11}),
                                           std::make_tuple(Device::Isotrak2, true, std::vector<int>{2, 4}),
                                           std::make_tuple(Device::Fastrak, false, std::vector<int>{2, 4, 1}),
                                           std::make_tuple(Device::Fastrak, true, std::vector<int>{2, 11}),
                                           std::make_tuple(Device::Fastrak, true, std::vector<int>{2, 11, 1})),
                         garbage_case_name);

TEST(RecordParser, RefusesBadSettings) {
  EXPECT_THROW(RecordParser(TrackerFormat::of(Device::Isotrak2), 0), InputError);
  EXPECT_THROW(RecordParser(TrackerFormat::of(Device::Fastrak, true, list({2, 16}))), InputError);
  TrackerFormat f = TrackerFormat::of(Device::Isotrak2, true, list({2, 4}));
  f.euler_full_scale_deg = 0;
  EXPECT_THROW(RecordParser(f, 115200), InputError);
}

TEST(RecordParser, EulerScaleIsConfigurable) {
  // With a 90 deg full scale one count is 90/32767 deg: 45 deg is 16383.5 -> 16384 counts.
  TrackerFormat f = TrackerFormat::of(Device::Isotrak2, true, list({2, 4}));
  f.euler_full_scale_deg = 90.0;
  IsotrakRecord r;
  r.position = glm::dvec3(0.0);
  r.attitude_deg = glm::dvec3(45.0, -90.0, 0.0);
  const auto back = decode_record(encode_record(r, f), f);
  ASSERT_TRUE(back.has_value());
  EXPECT_DOUBLE_EQ(back->attitude_deg->x, 16384 * 90.0 / 32767);
  EXPECT_DOUBLE_EQ(back->attitude_deg->y, -90.0);
  r.attitude_deg->x = 91;
  EXPECT_THROW(encode_record(r, f), std::invalid_argument);
}

}  // namespace
}  // namespace lumar::tracking
