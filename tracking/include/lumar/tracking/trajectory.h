#pragma once
// True sensor motion for the emulator: where each station's sensor is at a time,
// either a built-in sweep or a CSV of true poses.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "lumar/base/pose.h"
#include "lumar/base/time.h"

namespace lumar::tracking {

// T_transmitter_sensor of `station`'s sensor at time t (ns since the start). Polhemus
// transmitter frame (+Z down), metres.
using Trajectory = std::function<Pose(int station, Nanos t)>;

// "still"  a fixed pose.
// "sweep"  azimuth +-60 deg at 0.2 Hz, elevation +-15 deg, roll +-10 deg, and a 5 cm
//          circle of the position: head-like motion.
// "spin"   azimuth turning 36 deg/s forever (crosses +-180 deg every 10 s), elevation
//          20 deg: exercises the wrap of the Euler angles.
// Every station moves the same way, 10 cm further along +y per station and 0.5 s later.
// Positions stay within 0.5 m of the transmitter (inside every record format's range).
// Throws InputError for an unknown name.
Trajectory builtin_trajectory(const std::string& name);
const std::vector<std::string>& builtin_trajectory_names();

// A CSV of true poses in the poses.csv form of recordings: a header line, then
// time_ns,station,x,y,z,qw,qx,qy,qz (metres, unit quaternion). Poses between rows are
// interpolated (slerp, lerp); the rows play in a loop. A station without rows follows
// the first station in the file. Throws InputError naming the file and line for a
// missing file, a bad row, times that go backwards, or no rows.
Trajectory load_trajectory_csv(const std::filesystem::path& path);

}  // namespace lumar::tracking
