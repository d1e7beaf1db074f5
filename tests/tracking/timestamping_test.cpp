// Serial transmission times and record measurement times.
#include <gtest/gtest.h>

#include "lumar/tracking/timestamping.h"

namespace lumar::tracking {
namespace {

TEST(Timestamping, TransmissionTimeIsRoundedAndDoesNotOverflow) {
  EXPECT_EQ(byte_time(115200), 86'806);                 // 86805.56 ns
  EXPECT_EQ(byte_time(9600), 1'041'667);                // 1041666.67 ns
  EXPECT_EQ(transmission_time(47, 115200), 4'079'861);  // 4079861.1 ns
  EXPECT_EQ(transmission_time(0, 115200), 0);
  // 1e12 bytes: 1e22 / 115200 ns = 86805555555555555.6 -> no int64 overflow on the way.
  EXPECT_EQ(transmission_time(1'000'000'000'000, 115200), 86'805'555'555'555'556);
}

TEST(Timestamping, MeasurementTimeSubtractsFirstByteAndLatency) {
  // First byte in at 1 s; its own 86806 ns on the wire and 20 ms device latency come off.
  EXPECT_EQ(measurement_time(1'000'000'000, 115200, 20'000'000), 979'913'194);
  EXPECT_EQ(measurement_time(1'000'000'000, 100000, 0), 999'900'000);
}

}  // namespace
}  // namespace lumar::tracking
