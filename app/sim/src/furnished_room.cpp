#include "lumar/sim/furnished_room.h"

#include <array>

namespace lumar::sim {

namespace {

void append(Mesh& to, const Mesh& from) {
  const auto base = static_cast<std::uint32_t>(to.positions.size());
  to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
  to.normals.insert(to.normals.end(), from.normals.begin(), from.normals.end());
  for (std::uint32_t i : from.indices) to.indices.push_back(base + i);
}

}  // namespace

Mesh box_mesh(const glm::vec3& lo, const glm::vec3& hi) {
  Mesh box;
  // Each face: its outward normal and two in-plane axes (u x v = n), from the box's middle.
  const glm::vec3 mid = 0.5f * (lo + hi), half = 0.5f * (hi - lo);
  const std::array<glm::vec3, 6> normals{glm::vec3(1, 0, 0),  glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0),
                                         glm::vec3(0, -1, 0), glm::vec3(0, 0, 1),  glm::vec3(0, 0, -1)};
  for (const glm::vec3& n : normals) {
    const glm::vec3 u = std::abs(n.y) > 0.5f ? glm::vec3(0, 0, n.y) : glm::vec3(-n.z, 0, n.x);  // horizontal
    const glm::vec3 v = glm::cross(n, u);
    const glm::vec3 c = mid + n * half;
    const glm::vec3 du = u * half, dv = v * half;
    const auto first = static_cast<std::uint32_t>(box.positions.size());
    for (const glm::vec2 s : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
      box.positions.push_back(c + s.x * du + s.y * dv);
      box.normals.push_back(n);
    }
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) box.indices.push_back(first + i);
  }
  return box;
}

Mesh furnished_room(const Mesh& proxy) {
  Mesh room = proxy;
  const float far_z = proxy.bounds().first.z;
  for (glm::vec3& p : room.positions)
    if (p.z < far_z + 1e-4f) p.z -= 0.03f;
  append(room, box_mesh({-3.0f, 0.0f, -1.3f}, {-2.55f, 1.1f, -0.3f}));  // cabinet
  append(room, box_mesh({-0.9f, 0.0f, -0.9f}, {-0.5f, 0.25f, -0.5f}));  // a box on the floor
  append(room, box_mesh({-1.7f, 0.45f, -0.2f}, {-1.0f, 0.49f, 0.4f}));  // low table top
  for (const glm::vec2 leg :
       {glm::vec2(-1.65f, -0.15f), glm::vec2(-1.1f, -0.15f), glm::vec2(-1.65f, 0.3f), glm::vec2(-1.1f, 0.3f)})
    append(room, box_mesh({leg.x, 0.0f, leg.y}, {leg.x + 0.05f, 0.45f, leg.y + 0.05f}));
  return room;
}

}  // namespace lumar::sim
