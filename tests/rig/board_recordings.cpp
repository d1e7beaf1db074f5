#include "board_recordings.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <functional>
#include <map>
#include <memory>
#include <sstream>

#include "lumar/calib/camera_file.h"
#include "lumar/capture/session.h"
#include "test_paths.h"

namespace lumar::test {

namespace {

// Every setting that changes the recording, as text: its cache key.
std::string describe(const sim::BoardSynthSettings& s) {
  std::ostringstream out;
  out.precision(17);
  out << s.board.width << 'x' << s.board.height << ' ' << s.square << ' ' << s.seconds << ' ' << s.fps << ' '
      << s.tracker_noise_deg << ' ' << s.position_noise_m << ' ' << s.latency_ms << ' ' << s.assumed_latency_ms << ' '
      << s.image_noise << ' ' << s.codec << ' ' << s.seed;
  return out.str();
}

}  // namespace

sim::BoardSynthSettings noisy_board() {
  sim::BoardSynthSettings s;
  s.camera = calib::load_camera_file(source_dir() / "data/camera/webcam-640x480.yml").intrinsics;
  s.seconds = 12;
  return s;
}

sim::BoardSynthSettings clean_board() {
  sim::BoardSynthSettings s = noisy_board();
  s.tracker_noise_deg = 0;
  s.position_noise_m = 0;
  s.latency_ms = 35;
  return s;
}

std::filesystem::path board_recording(const sim::BoardSynthSettings& settings) {
  // Recordings made by an older build of the simulator are stale.
  const auto program = std::filesystem::read_symlink("/proc/self/exe");
  const auto stamp = std::filesystem::last_write_time(program).time_since_epoch().count();
  const std::string prefix = std::to_string(stamp) + "-";
  const std::string key = prefix + std::to_string(std::hash<std::string>{}(describe(settings)));
  const auto cache = std::filesystem::temp_directory_path() / "lumar-rig-test-recordings";
  const auto dir = cache / key;
  if (std::filesystem::exists(dir / "session.json")) return dir;
  std::filesystem::create_directories(cache);
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(cache, ec))
    if (entry.path().filename().string().rfind(prefix, 0) != 0) std::filesystem::remove_all(entry.path(), ec);
  const auto partial = cache / (key + ".partial-" + std::to_string(getpid()));
  std::filesystem::remove_all(partial, ec);
  sim::BoardSynthSettings s = settings;
  s.out = partial;
  sim::synthesize_board_recording(s);
  std::filesystem::rename(partial, dir, ec);  // another process may have won the race
  std::filesystem::remove_all(partial, ec);
  return dir;
}

tracking::Rig board_recording_truth(const std::filesystem::path& recording) {
  const auto session = capture::load_session_file(recording / "session.json");
  if (!session.synth_board) {
    ADD_FAILURE() << recording << ": no synth_board truth";
    return {};
  }
  return session.synth_board->truth;
}

const calib::RigRecording& loaded_board_recording(const sim::BoardSynthSettings& settings) {
  static std::map<std::string, std::unique_ptr<calib::RigRecording>> loaded;
  auto& slot = loaded[describe(settings)];
  if (!slot)
    slot = std::make_unique<calib::RigRecording>(
        calib::load_rig_recording(board_recording(settings), settings.board, settings.square));
  return *slot;
}

RigErrors rig_errors(const tracking::Rig& e, const tracking::Rig& t) {
  RigErrors r;
  r.offset_mm = 1e3 * glm::length(e.T_sensor_camera.translation - t.T_sensor_camera.translation);
  r.offset_deg = rotation_angle_deg(e.T_sensor_camera.rotation, t.T_sensor_camera.rotation);
  r.world_mm = 1e3 * glm::length(e.T_world_transmitter.translation - t.T_world_transmitter.translation);
  r.world_deg = rotation_angle_deg(e.T_world_transmitter.rotation, t.T_world_transmitter.rotation);
  r.latency_ms = nanos_to_seconds(e.latency - t.latency) * 1e3;
  return r;
}

}  // namespace lumar::test
