#include "lumar/scene/object_path.h"

#include <algorithm>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

namespace lumar {

namespace {

struct Parts {
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  double scale = 1.0;
  glm::dvec3 centre{0.0};  // world position of the model's centre
};

Parts split(const glm::dmat4& T, const glm::dvec3& centre_model) {
  const glm::dmat3 M(T);
  const double scale = glm::length(M[0]);
  return {glm::normalize(glm::quat_cast(M / scale)), scale, glm::dvec3(T * glm::dvec4(centre_model, 1.0))};
}

}  // namespace

ObjectPath::ObjectPath(std::vector<Key> keys, const glm::dvec3& centre_model)
    : keys_(std::move(keys)), centre_model_(centre_model) {}

glm::dmat4 ObjectPath::at(double t_s) const {
  if (keys_.empty()) return glm::dmat4(1.0);
  if (t_s <= keys_.front().t_s) return keys_.front().T_world_model;
  if (t_s >= keys_.back().t_s) return keys_.back().T_world_model;
  const auto next = std::upper_bound(keys_.begin(), keys_.end(), t_s, [](double t, const Key& k) { return t < k.t_s; });
  const Key& a = *(next - 1);
  const Key& b = *next;
  const double u = (t_s - a.t_s) / (b.t_s - a.t_s);
  const Parts pa = split(a.T_world_model, centre_model_), pb = split(b.T_world_model, centre_model_);
  const glm::dvec3 centre = glm::mix(pa.centre, pb.centre, u);
  const double scale = glm::mix(pa.scale, pb.scale, u);
  return glm::translate(glm::dmat4(1.0), centre) * glm::mat4_cast(glm::slerp(pa.rotation, pb.rotation, u)) *
         glm::scale(glm::dmat4(1.0), glm::dvec3(scale)) * glm::translate(glm::dmat4(1.0), -centre_model_);
}

}  // namespace lumar
