// The emulator speaks the protocol of TRACKER.md: talked to through the real serial
// transport, byte for byte, with expected records worked out by hand.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <span>
#include <thread>

#include "lumar/base/pose.h"
#include "lumar/tracking/record_codec.h"
#include "lumar/tracking/serial_transport.h"
#include "lumar/tracking/tracker_emulator.h"
#include "test_paths.h"

namespace lumar::tracking {
namespace {

// The "still" trajectory: station 1 at (0.30, 0, -0.10) m, station 2 10 cm further
// along y; azimuth 30, elevation 10, roll -5 degrees. No noise, so records are exact.
EmulatorSettings still_device(Device device = Device::Isotrak2, std::vector<int> stations = {1}) {
  EmulatorSettings e;
  e.device = device;
  e.stations = std::move(stations);
  e.trajectory = builtin_trajectory("still");
  e.orientation_noise_deg = 0;
  e.position_noise_m = 0;
  e.device_latency = 1'000'000;
  e.reinit_silence = 300'000'000;
  return e;
}

// A serial program talking to the emulator.
class Terminal {
 public:
  explicit Terminal(const std::string& path, int baud = 115200) : port_({path, baud, false}) {}

  void send(const std::string& bytes) { port_.write(bytes, 100'000'000); }

  // Everything that arrives within `window`.
  std::string listen(Nanos window) {
    std::string got;
    const Nanos end = monotonic_now() + window;
    for (Nanos now = monotonic_now(); now < end; now = monotonic_now()) {
      const ByteChunk c = port_.read(end - now);
      got.append(c.bytes.begin(), c.bytes.end());
    }
    return got;
  }

  // Sends `command` and reads until `n` bytes came (or 1 s passed).
  std::string ask(const std::string& command, std::size_t n) {
    send(command);
    std::string got;
    const Nanos end = monotonic_now() + 1'000'000'000;
    while (got.size() < n && monotonic_now() < end) {
      const ByteChunk c = port_.read(20'000'000);
      got.append(c.bytes.begin(), c.bytes.end());
    }
    return got;
  }

 private:
  SerialTransport port_;
};

std::optional<IsotrakRecord> decode(const std::string& bytes, const TrackerFormat& f) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data());
  return decode_record(std::span(p, bytes.size()), f);
}

const std::string kStation1Inches = "01   11.81   0.00  -3.94  30.00  10.00  -5.00\r\n";  // 0.30 / 0.0254 = 11.811
const std::string kStation1Cm = "01   30.00   0.00 -10.00  30.00  10.00  -5.00\r\n";
const std::string kStation2Inches = "02   11.81   3.94  -3.94  30.00  10.00  -5.00\r\n";

TEST(TrackerEmulator, AnswersStatusWithTheDevicesRecord) {
  TrackerEmulator isotrak(still_device());
  Terminal t(isotrak.port_path());
  EXPECT_EQ(t.ask("S", 21), "21S000  0  2.00    \r\n");
  EXPECT_EQ(t.ask("fuS", 21), "21S003  0  2.00    \r\n");  // binary and centimetres flags

  TrackerEmulator fastrak(still_device(Device::Fastrak));
  Terminal f(fastrak.port_path());
  const std::string status = f.ask("S", 55);
  ASSERT_EQ(status.size(), 55u);
  EXPECT_EQ(status.substr(0, 6), "21S000");
  EXPECT_EQ(status.substr(53), "\r\n");
  EXPECT_EQ(f.listen(50'000'000), "");  // nothing more
}

TEST(TrackerEmulator, PollSendsOneRecordPerActiveStation) {
  TrackerEmulator e(still_device(Device::Isotrak2, {1, 2}));
  Terminal t(e.port_path());
  EXPECT_EQ(t.ask("P", 94), kStation1Inches + kStation2Inches);
  EXPECT_EQ(t.ask("l\r", 7), "21l11\r\n");
  t.send("l2,0\r");
  EXPECT_EQ(t.ask("l\r", 7), "21l10\r\n");
  EXPECT_EQ(t.ask("P", 47), kStation1Inches);
  EXPECT_EQ(t.listen(50'000'000), "");
}

TEST(TrackerEmulator, FollowsUnitsListAndFormatCommands) {
  TrackerEmulator e(still_device());
  Terminal t(e.port_path());
  EXPECT_EQ(t.ask("uP", 47), kStation1Cm);
  EXPECT_EQ(t.ask("UP", 47), kStation1Inches);

  // List 2,11,1: the quaternion of Rz(30) Ry(10) Rx(-5), 4 decimals, w first.
  const glm::dquat q = polhemus_attitude_to_quat(30, 10, -5);
  OutputFormat list;
  list.output_list = {2, 11, 1};
  const std::string r = t.ask("O2,11,1\rP", 54);
  ASSERT_EQ(r.size(), 54u);
  const auto rec = decode(r, TrackerFormat::of(Device::Isotrak2, false, list));
  ASSERT_TRUE(rec && rec->quaternion);
  EXPECT_NEAR(rec->quaternion->w, q.w, 5e-5);
  EXPECT_NEAR(rec->quaternion->x, q.x, 5e-5);
  EXPECT_NEAR(rec->quaternion->y, q.y, 5e-5);
  EXPECT_NEAR(rec->quaternion->z, q.z, 5e-5);

  // Binary: the codec's length, and the same position within a count.
  const TrackerFormat binary = TrackerFormat::of(Device::Isotrak2, true, list);
  const std::string b = t.ask("fP", std::size_t(record_length(binary)));
  ASSERT_EQ(b.size(), std::size_t(record_length(binary)));
  EXPECT_EQ(std::uint8_t(b[0]), 0xB0);  // the start mark
  const auto brec = decode(b, binary);
  ASSERT_TRUE(brec && brec->position);
  EXPECT_NEAR(brec->position->x, 0.30 / 0.0254, 166.32 / 2.54 / 32767);
  EXPECT_NEAR(brec->position->z, -0.10 / 0.0254, 166.32 / 2.54 / 32767);

  // W: factory defaults at once.
  EXPECT_EQ(t.ask("WP", 47), kStation1Inches);
}

TEST(TrackerEmulator, FastrakTakesAStationInTheOutputList) {
  TrackerEmulator e(still_device(Device::Fastrak, {1, 2}));
  Terminal t(e.port_path());
  OutputFormat quat;
  quat.output_list = {2, 11, 1};
  t.send("O2,2,11,1\r");  // station 2 only
  const std::string r = t.ask("P", 47 + 54);
  ASSERT_EQ(r.size(), 101u);
  EXPECT_EQ(r.substr(0, 47), kStation1Inches);
  const auto rec = decode(r.substr(47), TrackerFormat::of(Device::Fastrak, false, quat));
  ASSERT_TRUE(rec);
  EXPECT_EQ(rec->station, 2);
}

TEST(TrackerEmulator, BoresightMakesTheCurrentOrientationZero) {
  TrackerEmulator e(still_device());
  Terminal t(e.port_path());
  EXPECT_EQ(t.ask("B1\rP", 47), "01   11.81   0.00  -3.94   0.00   0.00   0.00\r\n");
  EXPECT_EQ(t.ask("b1\rP", 47), kStation1Inches);
}

TEST(TrackerEmulator, CtrlYSilencesItThenRestoresPowerUpState) {
  TrackerEmulator e(still_device());  // 300 ms of reinitialisation
  Terminal t(e.port_path());
  t.send("u\x19");
  t.send("PS");
  EXPECT_EQ(t.listen(200'000'000), "");  // ignored while reinitialising
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  EXPECT_EQ(t.ask("P", 47), kStation1Inches);  // inches again
  EXPECT_EQ(e.counters().reinits, 1u);
}

// Streams from `C` for `window`: the bytes, and the time from just before `C` was sent
// to the last read. Nothing can arrive before the emulator writes it, and it writes
// no byte before the line could have carried it, so however late this thread runs,
// bytes <= elapsed * baud / 10 (+ one byte of rounding).
struct Stream {
  std::string bytes;
  Nanos elapsed = 0;
};

Stream stream_for(const std::string& path, int baud, Nanos window) {
  SerialTransport port({path, baud, false});
  Stream s;
  const Nanos before = monotonic_now();
  port.write("C", 100'000'000);
  Nanos last = before;
  for (const Nanos end = before + window; monotonic_now() < end;) {
    const ByteChunk c = port.read(10'000'000);
    s.bytes.append(c.bytes.begin(), c.bytes.end());
    last = c.arrival;
  }
  s.elapsed = last - before;
  return s;
}

TEST(TrackerEmulator, ContinuousOutputKeepsTheRateAndTheBaud) {
  // 115200 baud: the line has room; records come at 60 Hz (30 in half a second).
  {
    TrackerEmulator e(still_device());
    const Stream s = stream_for(e.port_path(), 115200, 500'000'000);
    const double records = double(s.bytes.size() / 47);  // the last one may be cut by the window
    EXPECT_LE(records, nanos_to_seconds(s.elapsed) * 60 + 1);
    EXPECT_GE(records, 15) << "far fewer records than 60 Hz";
    EXPECT_EQ(s.bytes.substr(0, 47), kStation1Inches);
  }
  // 9600 baud: 960 bytes a second, so 47-byte records come at most ~20 a second,
  // however fast the device would like to go.
  {
    EmulatorSettings settings = still_device();
    settings.baud = 9600;
    TrackerEmulator e(settings);
    const Stream s = stream_for(e.port_path(), 9600, 500'000'000);
    EXPECT_LE(double(s.bytes.size()), nanos_to_seconds(s.elapsed) * 960 + 1);
    EXPECT_GE(s.bytes.size(), 47u * 5) << "far fewer bytes than the line carries";
    EXPECT_EQ(s.bytes.substr(0, 47), kStation1Inches);
  }
}

TEST(TrackerEmulator, AVanishedPortComesBackUnderTheLink) {
  const lumar::test::Scratch scratch("tracker_emulator_link");
  const auto& dir = scratch.dir;
  EmulatorSettings s = still_device();
  s.link = dir / "tty";
  TrackerEmulator e(s);
  const std::string first = e.port_path();
  EXPECT_EQ(std::filesystem::read_symlink(s.link).string(), first);
  e.disconnect_for(100'000'000);
  const Nanos end = monotonic_now() + 2'000'000'000;
  while (e.connected() && monotonic_now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(s.link)));
  while (!e.connected() && monotonic_now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_TRUE(e.connected());
  EXPECT_EQ(std::filesystem::read_symlink(s.link).string(), e.port_path());
  Terminal t(s.link.string());
  EXPECT_EQ(t.ask("P", 47), kStation1Inches);
  EXPECT_EQ(e.counters().disconnects, 1u);
  e.stop();
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(s.link)));
}

TEST(TrackerEmulator, RejectsImpossibleSettings) {
  EmulatorSettings s = still_device();
  s.stations = {3};  // an ISOTRAK II has two
  EXPECT_THROW(TrackerEmulator{s}, InputError);
  s = still_device();
  s.faults.garbage_rate = 1.5;
  EXPECT_THROW(TrackerEmulator{s}, InputError);
}

}  // namespace
}  // namespace lumar::tracking
