// The driver against a device that vanishes, hangs, or was left streaming, and the
// transport's deadlines. Every wait has a deadline; the tests measure how long the
// calls a render loop makes can block.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <libserial/SerialPort.h>

#include <cstdio>
#include <future>
#include <thread>

#include "lumar/tracking/serial_transport.h"
#include "lumar/tracking/timestamping.h"
#include "test_paths.h"
#include "tracker_link.h"

namespace lumar::tracking::test {
namespace {

double ms(Nanos t) { return nanos_to_seconds(t) * 1e3; }

// Render-loop calls take no lock the reader thread can hold for long (5 ms, more in a
// sanitizer build: 28 ms were seen under ASan on a loaded machine).
const Nanos kRenderCallBudget = 5'000'000 * lumar::test::time_scale();

// Everything the driver does between finding the port again and the first record,
// by its settings: open, reset level 0, wait for quiet, status, configure, one record.
Nanos reset_time(const DriverSettings& d, double rate_hz) {
  return d.reopen_interval + d.quiet_limit + d.status_timeout + 4 * (d.command_gap + d.write_timeout / 100) +
         seconds_to_nanos(2.0 / rate_hz) + d.device_latency;
}

TEST(TrackerRecovery, ReconnectsAfterThePortVanishes) {
  const lumar::test::Scratch scratch("tracker_recovery_vanish");
  const auto& dir = scratch.dir;
  EmulatorSettings es = quick_emulator(Device::Isotrak2);
  es.link = dir / "tty";
  DriverSettings ds = quick_driver(TrackerFormat::of(Device::Isotrak2, true));
  SerialSettings serial;
  serial.path = es.link.string();

  Link link(es, ds, serial);
  ASSERT_TRUE(link.run_until([&] { return link.samples().size() >= 30; }, 5'000'000'000));
  const std::size_t before = link.samples().size();

  link.emulator().disconnect_for(400'000'000);
  ASSERT_TRUE(link.run_until([&] { return !link.emulator().connected(); }, 1'000'000'000));
  Nanos back = 0, first_new = 0;
  std::size_t at_back = 0;
  ASSERT_TRUE(link.run_until(
      [&] {
        if (!back && link.emulator().connected()) {
          back = monotonic_now();
          at_back = link.samples().size();
        }
        if (back && !first_new && link.samples().size() > at_back) first_new = monotonic_now();
        return back && link.samples().size() > before + 10;
      },
      5'000'000'000))
      << state_name(link.status().state) << ": " << link.status().message;
  const Nanos reconnect = first_new - back;  // the pty is back -> the first new sample is taken
  link.finish();

  const Nanos bound = ds.watchdog + reset_time(ds, es.rate_hz);
  std::printf(
      "  port back -> records flowing again: %.1f ms (bound: watchdog + reset = %.1f ms); vanished %llu, "
      "connects %llu; max take_samples %.3f ms, status %.3f ms; stop %.1f ms\n",
      ms(reconnect), ms(bound), (unsigned long long)link.status().vanished, (unsigned long long)link.status().connects,
      ms(link.max_take_time()), ms(link.max_status_time()), ms(link.stop_time()));
  EXPECT_LT(reconnect, bound);
  EXPECT_GE(link.status().vanished, 1u);
  EXPECT_EQ(link.status().connects, 2u);
  EXPECT_LT(link.max_take_time(), kRenderCallBudget);
  EXPECT_LT(link.max_status_time(), kRenderCallBudget);
  EXPECT_LT(link.stop_time(), ds.read_timeout + ds.write_timeout + 100'000'000);

  // After the reconnection the samples are the last records the emulator sent, all of
  // them, in order. (Records it sent into the new pty before the driver had reset it
  // were discarded, as they should be.)
  const auto sent = link.sent();
  const auto& got = link.samples();
  const std::size_t after = got.size() - at_back;
  ASSERT_GE(after, 10u);
  ASSERT_GE(sent.size(), after);
  for (std::size_t i = 0; i < after; ++i) EXPECT_TRUE(within(sent[sent.size() - after + i], got[at_back + i])) << i;
}

TEST(TrackerRecovery, AHungDeviceIsResetWithRisingForce) {
  EmulatorSettings es = quick_emulator(Device::Isotrak2);
  DriverSettings ds = quick_driver(TrackerFormat::of(Device::Isotrak2));
  ds.reinit_wait = 600'000'000;  // well beyond the emulator's 300 ms of Ctrl-Y silence

  Link link(es, ds);
  ASSERT_TRUE(link.run_until([&] { return link.samples().size() >= 20; }, 5'000'000'000));
  const std::size_t before = link.samples().size();
  const Nanos hung = monotonic_now();
  link.emulator().silence_for(60'000'000'000);  // only Ctrl-Y brings it back
  Nanos first_new = 0;                          // when the first sample measured after the hang was taken
  ASSERT_TRUE(link.run_until(
      [&] {
        if (!first_new && !link.samples().empty() && link.samples().back().time > hung) first_new = monotonic_now();
        return link.samples().size() > before + 20;
      },
      8'000'000'000))
      << state_name(link.status().state) << ": " << link.status().message;
  ASSERT_GT(first_new, 0);
  const Nanos recovered = first_new - hung;
  link.shut_down();

  const auto counters = link.emulator().counters();
  std::printf(
      "  hung -> records again after %.1f ms; watchdog faults %llu, failed resets %llu, Ctrl-Y %llu, highest "
      "reset level %d; max take_samples %.3f ms, status %.3f ms\n",
      ms(recovered), (unsigned long long)link.status().watchdog_faults,
      (unsigned long long)link.status().reset_attempts, (unsigned long long)counters.reinits, link.max_reset_level(),
      ms(link.max_take_time()), ms(link.max_status_time()));
  // Watchdog, three resets (each at most quiet_limit + status_timeout), the Ctrl-Y wait,
  // configuration and a record.
  EXPECT_LT(recovered, ds.watchdog + 3 * (ds.quiet_limit + ds.status_timeout) + ds.reinit_wait + 200'000'000);
  EXPECT_EQ(link.status().watchdog_faults, 1u);
  EXPECT_EQ(link.status().reset_attempts, 2u);  // "c" and CR + "c" could not wake it
  EXPECT_EQ(counters.reinits, 1u);              // Ctrl-Y did
  EXPECT_EQ(link.max_reset_level(), 2);
  EXPECT_EQ(link.status().state, TrackerState::stopped);
  EXPECT_LT(link.max_take_time(), kRenderCallBudget);
  EXPECT_LT(link.max_status_time(), kRenderCallBudget);
}

TEST(TrackerRecovery, StopsAStreamingDeviceBeforeConfiguringIt) {
  EmulatorSettings es = quick_emulator(Device::Isotrak2);
  es.continuous_at_power_up = true;  // streaming ASCII 2,4,1 before the driver opens the port
  OutputFormat output;
  output.output_list = {2, 11, 1};
  output.centimetres = true;
  DriverSettings ds = quick_driver(TrackerFormat::of(Device::Isotrak2, true, output));

  Link link(es, ds, {}, 200'000'000);
  ASSERT_TRUE(link.run_until([&] { return link.samples().size() >= 40; }, 5'000'000'000));
  link.finish();
  std::vector<SentRecord> configured;
  std::size_t before = 0;
  for (const auto& r : link.sent()) (r.format.binary ? configured.push_back(r) : void(++before));
  EXPECT_GT(before, 0u) << "the device was not streaming before the driver configured it";
  ASSERT_EQ(link.samples().size(), configured.size());
  for (std::size_t i = 0; i < configured.size(); ++i) EXPECT_TRUE(within(configured[i], link.samples()[i])) << i;
}

TEST(TrackerRecovery, PolledModeGetsOneRecordPerPoll) {
  EmulatorSettings es = quick_emulator(Device::Fastrak);
  es.stations = {1, 2};
  DriverSettings ds = quick_driver(TrackerFormat::of(Device::Fastrak));
  ds.stations = {1, 2};
  ds.continuous = false;
  ds.poll_rate_hz = 50;

  Link link(es, ds);
  ASSERT_TRUE(link.run_until([&] { return link.samples().size() >= 40; }, 5'000'000'000));
  link.finish();
  const auto sent = link.sent();
  ASSERT_EQ(link.samples().size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    EXPECT_TRUE(within(sent[i], link.samples()[i])) << i;
    EXPECT_EQ(sent[i].values.station, int(i % 2) + 1);  // P answers for each active station
  }
}

TEST(TrackerRecovery, StopIsPromptEvenDuringALongReset) {
  EmulatorSettings es = quick_emulator(Device::Isotrak2);
  DriverSettings ds = quick_driver(TrackerFormat::of(Device::Isotrak2));
  ds.reinit_wait = 30'000'000'000;  // a long Ctrl-Y wait that stop() must cut short

  TrackerEmulator emulator(es);
  emulator.silence_for(60'000'000'000);
  TrackerDriver driver(ds, serial_port({emulator.port_path(), es.baud, false}));
  driver.start();
  const Nanos end = monotonic_now() + 5'000'000'000;
  while (driver.status().reset_level < 2 && monotonic_now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(driver.status().reset_level, 2) << driver.status().message;
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // inside the 30 s wait
  const Nanos t0 = monotonic_now();
  driver.stop();
  const Nanos took = monotonic_now() - t0;
  std::printf("  stop() during a 30 s Ctrl-Y wait took %.2f ms (read timeout %.0f ms)\n", ms(took),
              ms(ds.read_timeout));
  EXPECT_LT(took, ds.read_timeout + ds.write_timeout + 100'000'000);
  EXPECT_EQ(driver.status().state, TrackerState::stopped);
}

TEST(SerialTransportDeadlines, ReadWaitsNoLongerThanItsTimeout) {
  TrackerEmulator emulator(quick_emulator(Device::Isotrak2));  // silent: not continuous
  SerialTransport port({emulator.port_path(), 115200, false});
  Nanos worst = 0;
  for (Nanos timeout : {Nanos(0), Nanos(5'000'000), Nanos(50'000'000)}) {
    const Nanos t0 = monotonic_now();
    const ByteChunk c = port.read(timeout);
    const Nanos took = monotonic_now() - t0;
    EXPECT_TRUE(c.bytes.empty());
    EXPECT_GE(took, timeout - 1'000'000);
    worst = std::max(worst, took - timeout);
  }
  std::printf("  idle read overshoots its timeout by at most %.3f ms\n", ms(worst));
  EXPECT_LT(worst, 50'000'000);

  // The status record comes back through LibSerial, whole, stamped after it arrived.
  const Nanos sent_at = monotonic_now();
  port.write("S", 100'000'000);
  std::string reply;
  Nanos last_arrival = 0;
  for (Nanos end = monotonic_now() + 1'000'000'000; reply.size() < 21 && monotonic_now() < end;) {
    const ByteChunk c = port.read(50'000'000);
    reply.append(c.bytes.begin(), c.bytes.end());
    if (!c.bytes.empty()) last_arrival = c.arrival;
  }
  ASSERT_EQ(reply.size(), 21u);
  EXPECT_EQ(reply.substr(0, 3), "21S");
  EXPECT_EQ(reply.substr(19), "\r\n");
  EXPECT_GE(last_arrival - sent_at, transmission_time(21, 115200));
}

TEST(SerialTransportDeadlines, AVanishingPortEndsAReadAtOnce) {
  TrackerEmulator emulator(quick_emulator(Device::Isotrak2));
  SerialTransport port({emulator.port_path(), 115200, false});
  auto pull = std::async(std::launch::async, [&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    emulator.disconnect_for(10'000'000'000);
  });
  const Nanos t0 = monotonic_now();
  EXPECT_THROW(port.read(2'000'000'000), DeviceVanished);
  const Nanos took = monotonic_now() - t0;
  pull.get();
  std::printf("  a read with a 2 s timeout ended %.2f ms after it started (the port vanished at 50 ms)\n", ms(took));
  EXPECT_LT(took, 1'000'000'000);
  EXPECT_THROW(port.write("c", 100'000'000), DeviceVanished);
  port.close();
  EXPECT_THROW(port.read(10'000'000), DeviceVanished);
  EXPECT_THROW(SerialTransport({"/dev/lumar-no-such-port", 115200, false}), DeviceVanished);
  EXPECT_THROW(SerialTransport({emulator.port_path(), 12345, false}), InputError);
  try {
    SerialTransport not_a_tty({"/dev/null", 115200, false});
    ADD_FAILURE() << "/dev/null opened as a serial port";
  } catch (const DeviceVanished&) {
    ADD_FAILURE() << "a wrong path is not a vanished device";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("not a serial port"), std::string::npos) << e.what();
  }
}

// LibSerial leaves TIOCEXCL set (a non-root process could not reopen the port); the
// transport clears it. Checked with TIOCGEXCL, since root ignores the flag anyway.
TEST(SerialTransportDeadlines, LeavesThePortReopenable) {
  TrackerEmulator emulator(quick_emulator(Device::Isotrak2));
  auto exclusive = [&] {
    const int fd = ::open(emulator.port_path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    EXPECT_GE(fd, 0);
    int excl = -1;
    EXPECT_EQ(::ioctl(fd, TIOCGEXCL, &excl), 0);
    ::close(fd);
    return excl;
  };
  {
    LibSerial::SerialPort plain;
    plain.Open(emulator.port_path());
    EXPECT_EQ(exclusive(), 1) << "LibSerial no longer sets TIOCEXCL; the workaround may go";
  }
  {
    SerialTransport port({emulator.port_path(), 115200, false});
    EXPECT_EQ(exclusive(), 0);
  }
}

}  // namespace
}  // namespace lumar::tracking::test
