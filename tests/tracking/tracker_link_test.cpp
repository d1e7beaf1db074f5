// Emulator -> pty -> LibSerial transport -> driver -> poses, end to end, with and
// without faults. Each test uses a fresh pty.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include "lumar/tracking/record_codec.h"
#include "test_paths.h"
#include "tracker_link.h"

namespace lumar::tracking::test {
namespace {

struct LinkCase {
  Device device;
  bool binary;
  bool centimetres;
  std::vector<int> list;
  std::vector<int> stations;
};

void PrintTo(const LinkCase& c, std::ostream* os) {
  *os << device_name(c.device) << (c.binary ? " binary" : " ASCII") << (c.centimetres ? " cm" : " in") << " list";
  for (int i : c.list) *os << ' ' << i;
  *os << ", " << c.stations.size() << " station(s)";
}

std::string case_name(const testing::TestParamInfo<LinkCase>& info) {
  const LinkCase& c = info.param;
  std::string name = device_name(c.device) + (c.binary ? "_binary_" : "_ascii_") + (c.centimetres ? "cm_" : "in_");
  for (int i : c.list) name += std::to_string(i);
  return name + "_stations" + std::to_string(c.stations.size());
}

class CleanLink : public testing::TestWithParam<LinkCase> {};

// No faults: every record the emulator put on the line comes out of the driver, in
// order, equal to what the emulator encoded within the format's quantisation, and
// stamped with the emulator's measurement time.
TEST_P(CleanLink, EveryRecordArrivesWithItsValues) {
  const LinkCase& c = GetParam();
  EmulatorSettings es = quick_emulator(c.device);
  es.stations = c.stations;
  OutputFormat output;
  output.output_list = c.list;
  output.centimetres = c.centimetres;
  DriverSettings ds = quick_driver(TrackerFormat::of(c.device, c.binary, output));
  ds.stations = c.stations;

  Link link(es, ds);
  ASSERT_TRUE(link.run_until([&] { return link.samples().size() >= 60; }, 5'000'000'000))
      << "state " << state_name(link.status().state) << ": " << link.status().message;
  link.finish();

  const auto sent = link.sent();
  const auto& got = link.samples();
  ASSERT_GE(sent.size(), 60u);
  for (const auto& r : sent) {
    // The driver configured the device before it started sending.
    EXPECT_EQ(r.format.binary, c.binary);
    EXPECT_EQ(r.format.output.output_list, c.list);
    EXPECT_EQ(r.format.output.centimetres, c.centimetres);
    EXPECT_FALSE(r.dropped || r.cut_short || r.garbage_bytes > 0) << "record " << r.sequence;
  }
  ASSERT_EQ(got.size(), sent.size()) << "records lost or invented";
  const Tolerance tol = quantisation(ds.format);
  Mismatch worst;
  std::vector<double> time_error_ms;
  std::vector<int> per_station(10, 0);
  for (std::size_t i = 0; i < sent.size(); ++i) {
    const Mismatch m = mismatch(sent[i], got[i]);
    worst.position_m = std::max(worst.position_m, m.position_m);
    worst.angle_deg = std::max(worst.angle_deg, m.angle_deg);
    EXPECT_EQ(got[i].station, sent[i].values.station) << "record " << i;
    EXPECT_TRUE(within(sent[i], got[i])) << "record " << i << ": position off by " << m.position_m << " m, rotation by "
                                         << m.angle_deg << " deg";
    time_error_ms.push_back(nanos_to_seconds(got[i].time - sent[i].measured) * 1e3);
    ++per_station[std::size_t(got[i].station)];
  }
  for (int s : c.stations) EXPECT_GT(per_station[std::size_t(s)], 0) << "no record of station " << s;
  // Quantisation is not zero: the comparison is not vacuous.
  EXPECT_GT(worst.position_m, 0.0);
  EXPECT_LE(worst.position_m, tol.position_m);
  EXPECT_LE(worst.angle_deg, tol.angle_deg);
  EXPECT_EQ(link.status().rejected_records, 0u);

  // Host-side delays only ever make a record look later: the corrected time is never
  // before the measurement (up to rounding), and typically within a few ms of it.
  std::sort(time_error_ms.begin(), time_error_ms.end());
  const double median = time_error_ms[time_error_ms.size() / 2];
  EXPECT_GE(time_error_ms.front(), -0.01);
  EXPECT_LT(median, 20.0);
  std::printf(
      "  %zu records sent, %zu received; worst error %.2e m, %.4f deg; time error ms: min %.3f median %.3f "
      "max %.3f; skipped %llu bytes\n",
      sent.size(), got.size(), worst.position_m, worst.angle_deg, time_error_ms.front(), median, time_error_ms.back(),
      (unsigned long long)link.status().skipped_bytes);
}

INSTANTIATE_TEST_SUITE_P(Formats, CleanLink,
                         testing::Values(LinkCase{Device::Isotrak2, false, false, {2, 4, 1}, {1}},
                                         LinkCase{Device::Isotrak2, false, true, {2, 4, 1}, {1, 2}},
                                         LinkCase{Device::Isotrak2, false, false, {2, 11, 1}, {1}},
                                         LinkCase{Device::Isotrak2, false, true, {2, 11, 1}, {1}},
                                         LinkCase{Device::Isotrak2, true, false, {2, 4, 1}, {1}},
                                         LinkCase{Device::Isotrak2, true, true, {2, 4, 1}, {1}},
                                         LinkCase{Device::Isotrak2, true, false, {2, 11, 1}, {1, 2}},
                                         LinkCase{Device::Isotrak2, true, true, {2, 11, 1}, {1}},
                                         LinkCase{Device::Fastrak, false, true, {2, 11, 1}, {1, 2}},
                                         LinkCase{Device::Fastrak, true, false, {2, 4, 1}, {1, 2}}),
                         case_name);

// 1 % of the bytes replaced by garbage: every record garbage did not touch is recovered.
TEST(FaultyLink, GarbageLosesOnlyTheRecordsItTouches) {
  EmulatorSettings es = quick_emulator(Device::Isotrak2);
  es.rate_hz = 200;
  es.faults.garbage_rate = 0.01;
  es.seed = 7;
  DriverSettings ds = quick_driver(TrackerFormat::of(Device::Isotrak2));

  Link link(es, ds);
  ASSERT_TRUE(link.run_until([&] { return link.samples().size() >= 300; }, 8'000'000'000))
      << state_name(link.status().state) << ": " << link.status().message;
  link.finish();

  const auto sent = link.sent();
  const auto& got = link.samples();
  const auto good = intact(sent);
  std::size_t damaged = 0, garbage = 0;
  for (const auto& r : sent) {
    damaged += r.garbage_bytes > 0;
    garbage += std::size_t(r.garbage_bytes);
  }
  // Walk both streams in order: each received sample is the next sent record it matches.
  std::size_t cursor = 0, matched_intact = 0, matched_damaged = 0, unmatched = 0;
  for (const auto& s : got) {
    std::size_t k = cursor;
    while (k < sent.size() && !within(sent[k], s)) ++k;
    if (k == sent.size()) {
      ++unmatched;  // a damaged record that still decoded, with changed digits
      continue;
    }
    // Whatever was skipped over must have been damaged.
    for (std::size_t j = cursor; j < k; ++j) EXPECT_GT(sent[j].garbage_bytes, 0) << "intact record " << j << " lost";
    (sent[k].garbage_bytes == 0 ? matched_intact : matched_damaged) += 1;
    cursor = k + 1;
  }
  std::printf(
      "  %zu records sent (%zu bytes of garbage in %zu of them), %zu intact; received %zu: %zu intact, %zu "
      "damaged but equal, %zu altered; driver: %llu rejected candidates, %llu skipped bytes\n",
      sent.size(), garbage, damaged, good.size(), got.size(), matched_intact, matched_damaged, unmatched,
      (unsigned long long)link.status().rejected_records, (unsigned long long)link.status().skipped_bytes);
  EXPECT_GT(damaged, 50u) << "the fault injection did not bite";
  EXPECT_EQ(matched_intact, good.size()) << "every untouched record must be recovered";
  EXPECT_LE(matched_damaged + unmatched, damaged);
  EXPECT_GT(link.status().skipped_bytes, garbage);
}

// Dropped records are simply missing; the rest arrive.
TEST(FaultyLink, DroppedRecordsAreTheOnlyOnesMissing) {
  EmulatorSettings es = quick_emulator(Device::Isotrak2);
  es.faults.drop_rate = 0.1;
  DriverSettings ds = quick_driver(TrackerFormat::of(Device::Isotrak2, true));

  Link link(es, ds);
  ASSERT_TRUE(link.run_until([&] { return link.samples().size() >= 60; }, 5'000'000'000));
  link.finish();
  const auto sent = link.sent();
  const auto good = intact(sent);
  ASSERT_EQ(link.samples().size(), good.size());
  for (std::size_t i = 0; i < good.size(); ++i) EXPECT_TRUE(within(good[i], link.samples()[i])) << i;
  EXPECT_LT(good.size(), sent.size());
}

}  // namespace
}  // namespace lumar::tracking::test
