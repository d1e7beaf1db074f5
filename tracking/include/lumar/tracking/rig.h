#pragma once
// The tracked camera rig: where the transmitter sits in the room, where the camera
// sits on the sensor, and how late the tracker reports.
#include <nlohmann/json_fwd.hpp>

#include "lumar/base/pose.h"
#include "lumar/base/time.h"

namespace lumar::tracking {

struct Rig {
  Pose T_world_transmitter;
  Pose T_sensor_camera;
  Nanos latency = 0;  // tracker reading time = true sensor time + latency

  Pose camera_pose(const Pose& T_transmitter_sensor) const {
    return T_world_transmitter * T_transmitter_sensor * T_sensor_camera;
  }
  Pose sensor_pose(const Pose& T_world_camera) const {
    return T_world_transmitter.inverse() * T_world_camera * T_sensor_camera.inverse();
  }
};

// JSON form of a pose: {"translation": [x, y, z], "rotation_wxyz": [w, x, y, z]}.
nlohmann::json pose_to_json(const Pose& pose);
// Throws InputError naming `what` when the JSON is not a valid pose.
Pose pose_from_json(const nlohmann::json& j, const std::string& what);

}  // namespace lumar::tracking
