// The smaller parts of the tracker side: the shared measurement model, trajectories,
// the lock-free sample ring, device classification and driver settings.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include "lumar/base/error.h"
#include "lumar/tracking/device_enumeration.h"
#include "lumar/tracking/measurement_model.h"
#include "lumar/tracking/spsc_ring.h"
#include "lumar/tracking/tracker_driver.h"
#include "lumar/tracking/trajectory.h"
#include "test_paths.h"

namespace lumar::tracking {
namespace {

TEST(MeasurementNoise, HasTheRequestedSizeAndRepeatsForASeed) {
  MeasurementNoise noise(0.75, 0.0025, 42), again(0.75, 0.0025, 42);
  Pose truth;
  truth.rotation = polhemus_attitude_to_quat(40, -10, 5);
  truth.translation = {0.2, -0.1, 0.3};
  const int n = 20000;
  double sum_angle2 = 0, sum_pos2 = 0;
  for (int i = 0; i < n; ++i) {
    const Pose p = noise.apply(truth);
    const Pose q = again.apply(truth);
    ASSERT_EQ(p.translation, q.translation);
    sum_angle2 += std::pow(rotation_angle_deg(p.rotation, truth.rotation), 2);
    const glm::dvec3 d = p.translation - truth.translation;
    sum_pos2 += glm::dot(d, d) / 3;
  }
  // RMS of n samples: relative standard error about 1 / sqrt(2 n) = 0.5 %.
  EXPECT_NEAR(std::sqrt(sum_angle2 / n), 0.75, 0.02);
  EXPECT_NEAR(std::sqrt(sum_pos2 / n), 0.0025, 0.00005);
  EXPECT_THROW(MeasurementNoise(-1, 0, 1), InputError);
}

TEST(MeasurementModel, DeviceRecordUsesDeviceUnitsAndOneQuaternionSign) {
  Pose p;
  p.rotation = -polhemus_attitude_to_quat(170, 20, -30);  // the other sign of the same rotation
  p.translation = {0.254, -0.0254, 0.0};
  OutputFormat inches;
  const IsotrakRecord r = device_record(p, inches, 2, ' ');
  EXPECT_EQ(r.station, 2);
  EXPECT_NEAR(r.position->x, 10.0, 1e-12);
  EXPECT_NEAR(r.position->y, -1.0, 1e-12);
  EXPECT_GE(r.quaternion->w, 0.0);
  EXPECT_NEAR(r.attitude_deg->x, 170, 1e-9);
  EXPECT_NEAR(r.attitude_deg->y, 20, 1e-9);
  EXPECT_NEAR(r.attitude_deg->z, -30, 1e-9);
  OutputFormat cm;
  cm.centimetres = true;
  EXPECT_NEAR(device_record(p, cm, 1).position->x, 25.4, 1e-12);
}

TEST(Trajectory, BuiltInsStayInRangeAndStationsDiffer) {
  for (const auto& name : builtin_trajectory_names()) {
    const Trajectory t = builtin_trajectory(name);
    for (Nanos k = 0; k < 200; ++k) {
      const Nanos time = k * 97'000'000;
      const Pose p = t(1, time);
      EXPECT_LT(glm::length(p.translation), 0.5) << name;
      EXPECT_NEAR(glm::length(p.rotation), 1.0, 1e-12);
      EXPECT_NEAR(t(2, time).translation.y - t(1, time).translation.y, 0.1, name == "sweep" ? 0.11 : 1e-12);
    }
  }
  // spin crosses the +-180 degree azimuth wrap.
  const Trajectory spin = builtin_trajectory("spin");
  EXPECT_NEAR(quat_to_polhemus_attitude(spin(1, 4'900'000'000).rotation).x, 176.4, 1e-6);
  EXPECT_NEAR(quat_to_polhemus_attitude(spin(1, 5'100'000'000).rotation).x, -176.4, 1e-6);
  EXPECT_THROW(builtin_trajectory("loop-the-loop"), InputError);
}

TEST(Trajectory, CsvIsInterpolatedAndLooped) {
  const lumar::test::Scratch scratch("trajectory_csv");
  const auto& dir = scratch.dir;
  const auto file = dir / "truth.csv";
  const glm::dquat q90 = axis_angle_deg({0, 0, 1}, 90);
  {
    std::ofstream out(file);
    out << "time_ns,station,x,y,z,qw,qx,qy,qz\n";
    out << "0,1,0,0,0,1,0,0,0\n";
    out << "1000000000,1,1,0,0," << q90.w << ",0,0," << q90.z << "\n";
  }
  const Trajectory t = load_trajectory_csv(file);
  const Pose mid = t(1, 500'000'000);
  EXPECT_NEAR(mid.translation.x, 0.5, 1e-12);
  EXPECT_NEAR(rotation_angle_deg(mid.rotation, glm::dquat(1, 0, 0, 0)), 45, 1e-9);
  EXPECT_NEAR(t(1, 1'250'000'000).translation.x, 0.25, 1e-12);  // looped
  EXPECT_NEAR(t(2, 250'000'000).translation.x, 0.25, 1e-12);    // station 2 follows station 1

  {
    std::ofstream out(dir / "bad.csv");
    out << "time_ns,station,x,y,z,qw,qx,qy,qz\n0,1,0,0,0,1,0,0,0\n5,1,zero,0,0,1,0,0,0\n";
  }
  try {
    load_trajectory_csv(dir / "bad.csv");
    FAIL() << "a bad row was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_trajectory_csv(dir / "missing.csv"), InputError);
}

TEST(SpscRing, KeepsOrderRefusesWhenFullAndCrossesThreads) {
  SpscRing<int> ring(3);
  EXPECT_TRUE(ring.push(1));
  EXPECT_TRUE(ring.push(2));
  EXPECT_TRUE(ring.push(3));
  EXPECT_FALSE(ring.push(4));
  EXPECT_EQ(ring.pop(), 1);
  EXPECT_TRUE(ring.push(4));
  EXPECT_EQ(ring.pop(), 2);
  EXPECT_EQ(ring.pop(), 3);
  EXPECT_EQ(ring.pop(), 4);
  EXPECT_EQ(ring.pop(), std::nullopt);

  // One producer, one consumer: every item arrives once, in order.
  SpscRing<std::int64_t> shared(64);
  constexpr std::int64_t kItems = 200000;
  std::thread producer([&] {
    for (std::int64_t i = 0; i < kItems;)
      if (shared.push(i)) ++i;
  });
  std::int64_t expected = 0;
  while (expected < kItems) {
    if (auto v = shared.pop()) {
      ASSERT_EQ(*v, expected++);
    }
  }
  producer.join();
}

TEST(DeviceEnumeration, KnowsPolhemusAndAdapterVendors) {
  EXPECT_EQ(polhemus_model(0x0f44, 0x0002), "Polhemus Fastrak");
  EXPECT_EQ(polhemus_model(0x0f44, 0xef12), "Polhemus Patriot");
  EXPECT_EQ(polhemus_model(0x0f44, 0xff12), "Polhemus Liberty");
  EXPECT_EQ(polhemus_model(0x0f44, 0x1234), "Polhemus device 0x1234");
  EXPECT_EQ(polhemus_model(0x0403, 0x0002), std::nullopt);
  EXPECT_EQ(usb_serial_vendor(0x0403), "FTDI");
  EXPECT_EQ(usb_serial_vendor(0x067b), "Prolific");
  EXPECT_EQ(usb_serial_vendor(0x1a86), "CH340");
  EXPECT_EQ(usb_serial_vendor(0x10c4), "Silicon Labs CP210x");
  EXPECT_EQ(usb_serial_vendor(0x0f44), std::nullopt);

  // Whatever this machine has: the listing works and names only ports that exist.
  const DeviceInventory inv = list_devices();
  for (const auto& p : inv.serial_ports) EXPECT_TRUE(std::filesystem::exists(p.path)) << p.path;
  for (const auto& d : inv.polhemus) EXPECT_EQ(d.vendor, kPolhemusVendor);
  for (const auto& d : inv.usb_serial) EXPECT_TRUE(usb_serial_vendor(d.vendor).has_value());
}

TEST(DriverSettings, RejectsUnusableSettings) {
  DriverSettings d;
  EXPECT_NO_THROW(validate_driver_settings(d));
  d.stations = {3};  // an ISOTRAK II has two
  EXPECT_THROW(validate_driver_settings(d), InputError);
  d = DriverSettings{};
  d.watchdog = 0;
  EXPECT_THROW(validate_driver_settings(d), InputError);
  d = DriverSettings{};
  d.continuous = false;
  d.poll_rate_hz = 0;
  EXPECT_THROW(validate_driver_settings(d), InputError);
  d = DriverSettings{};
  d.format.output.output_list = {2, 99};
  EXPECT_THROW(validate_driver_settings(d), InputError);
}

}  // namespace
}  // namespace lumar::tracking
