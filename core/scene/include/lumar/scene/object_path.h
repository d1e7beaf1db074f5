#pragma once
// An animated object's path, its keys finished (bottom-centre origin and on_floor
// applied with the mesh and the proxy): the pose at any time of the recording. Between
// keys the middle of the model's bounding box moves in a straight line and the rotation
// turns by slerp, so a model that rests on a flat floor at both keys and turns about the
// vertical rests on it all the way; before the first key and after the last it stands at
// that key.
#include <glm/glm.hpp>
#include <vector>

namespace lumar {

class ObjectPath {
 public:
  struct Key {
    double t_s = 0.0;               // seconds of recording time, strictly increasing
    glm::dmat4 T_world_model{1.0};  // a rotation, a uniform scale and a translation
  };

  ObjectPath() = default;
  // `centre_model`: the model point that moves in straight lines (its box's middle).
  ObjectPath(std::vector<Key> keys, const glm::dvec3& centre_model);

  bool empty() const { return keys_.empty(); }
  const std::vector<Key>& keys() const { return keys_; }
  double start_s() const { return keys_.empty() ? 0.0 : keys_.front().t_s; }
  double end_s() const { return keys_.empty() ? 0.0 : keys_.back().t_s; }
  // T_world_model at t seconds; the identity when empty.
  glm::dmat4 at(double t_s) const;

 private:
  std::vector<Key> keys_;
  glm::dvec3 centre_model_{0.0};
};

}  // namespace lumar
