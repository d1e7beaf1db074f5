#include "board_recordings.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <memory>

#include "lumar/capture/session.h"
#include "test_paths.h"

namespace lumar::test {

std::filesystem::path board_recording(const std::string& extra_args) {
  const auto binary = lumar_binary();
  const auto stamp = std::filesystem::last_write_time(binary).time_since_epoch().count();
  const std::string prefix = std::to_string(stamp) + "-";
  const std::string key = prefix + std::to_string(std::hash<std::string>{}(extra_args));
  const auto cache = std::filesystem::temp_directory_path() / "lumar-rig-test-recordings";
  const auto dir = cache / key;
  if (std::filesystem::exists(dir / "session.json")) return dir;
  std::filesystem::create_directories(cache);
  // Recordings made by an older binary are stale.
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(cache, ec))
    if (entry.path().filename().string().rfind(prefix, 0) != 0) std::filesystem::remove_all(entry.path(), ec);
  const auto partial = cache / (key + ".partial-" + std::to_string(getpid()));
  std::filesystem::remove_all(partial);
  const std::string command = "'" + binary.string() + "' synth --board 9x6 --square 0.025 --camera '" +
                              (source_dir() / "data/camera/webcam-640x480.yml").string() + "' --out '" +
                              partial.string() + "' " + extra_args + " > '" + partial.string() + ".log' 2>&1";
  if (std::system(command.c_str()) != 0) {
    ADD_FAILURE() << "failed: " << command;
    return {};
  }
  std::filesystem::rename(partial, dir, ec);  // another process may have won the race
  std::filesystem::remove_all(partial);
  std::filesystem::remove(partial.string() + ".log", ec);
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

const calib::RigRecording& loaded_board_recording(const std::string& extra_args) {
  static std::map<std::string, std::unique_ptr<calib::RigRecording>> loaded;
  auto& slot = loaded[extra_args];
  if (!slot)
    slot = std::make_unique<calib::RigRecording>(
        calib::load_rig_recording(board_recording(extra_args), cv::Size(9, 6), 0.025));
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
