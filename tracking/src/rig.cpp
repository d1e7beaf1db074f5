#include "lumar/tracking/rig.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "lumar/base/error.h"

namespace lumar::tracking {

nlohmann::json pose_to_json(const Pose& p) {
  return {{"translation", {p.translation.x, p.translation.y, p.translation.z}},
          {"rotation_wxyz", {p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z}}};
}

Pose pose_from_json(const nlohmann::json& j, const std::string& what) {
  try {
    const auto t = j.at("translation").get<std::array<double, 3>>();
    const auto q = j.at("rotation_wxyz").get<std::array<double, 4>>();
    Pose p;
    p.translation = {t[0], t[1], t[2]};
    const glm::dquat raw(q[0], q[1], q[2], q[3]);
    const double n = glm::length(raw);
    if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-3)
      throw InputError(what + ": rotation_wxyz is not a unit quaternion");
    p.rotation = raw / n;
    if (!p.is_finite()) throw InputError(what + ": pose holds a non-finite number");
    return p;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(what + ": expected {\"translation\": [x,y,z], \"rotation_wxyz\": [w,x,y,z]} (" +
                     std::string(e.what()) + ")");
  }
}

}  // namespace lumar::tracking
