#pragma once
// The path of a camera sweeping the sphere from one point: a spiral of several
// elevation rings, from below the horizon to near the zenith, with a little roll so
// that no two rings look alike. Used to synthesise sweeps and by their tests.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace lumar::calib {

struct SweepPath {
  double elevation_min_deg = -62.0;  // optical axis at the start (below the horizon)
  double elevation_max_deg = 78.0;   // and at the end
  double turns = 5.0;                // full azimuth turns (about one per elevation ring)
  double roll_wobble_deg = 4.0;      // amplitude of the roll about the optical axis
};

// R_world_camera (OpenCV camera axes, world +Y up) at s in [0, 1] along the path.
glm::dquat sweep_rotation(double s, const SweepPath& path = {});

}  // namespace lumar::calib
