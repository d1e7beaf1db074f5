#include "lumar/sim/furnished_room.h"

#include <array>
#include <vector>

namespace lumar::sim {

namespace {

void append(Mesh& to, const Mesh& from) {
  const auto base = static_cast<std::uint32_t>(to.positions.size());
  to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
  to.normals.insert(to.normals.end(), from.normals.begin(), from.normals.end());
  for (std::uint32_t i : from.indices) to.indices.push_back(base + i);
}

// A flat quad a-b-c-d whose front faces along `normal`.
Mesh quad_mesh(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
               const glm::vec3& normal) {
  Mesh quad;
  quad.positions = {a, b, c, d};
  quad.normals.assign(4, normal);
  const bool front = glm::dot(glm::cross(b - a, c - a), normal) > 0;  // counter-clockwise = front
  quad.indices = front ? std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3} : std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2};
  return quad;
}

// The wall z = z_wall (facing +z, x0..x1, y0..y1) with a recess `depth` deep over
// [hx0, hx1] x [hy0, hy1]: the wall around the opening and the recess's five faces.
Mesh wall_with_recess(float z_wall, float x0, float x1, float y0, float y1, float hx0, float hx1, float hy0, float hy1,
                      float depth) {
  Mesh wall;
  const glm::vec3 out(0, 0, 1);
  auto rect = [&](float ax, float ay, float bx, float by, float z) {
    append(wall, quad_mesh({ax, ay, z}, {bx, ay, z}, {bx, by, z}, {ax, by, z}, out));
  };
  rect(x0, y0, hx0, y1, z_wall);    // left of the opening
  rect(hx1, y0, x1, y1, z_wall);    // right of it
  rect(hx0, y0, hx1, hy0, z_wall);  // below
  rect(hx0, hy1, hx1, y1, z_wall);  // above
  const float zb = z_wall - depth;
  rect(hx0, hy0, hx1, hy1, zb);  // the recess's back
  append(wall, quad_mesh({hx0, hy0, zb}, {hx0, hy1, zb}, {hx0, hy1, z_wall}, {hx0, hy0, z_wall}, {1, 0, 0}));
  append(wall, quad_mesh({hx1, hy0, zb}, {hx1, hy1, zb}, {hx1, hy1, z_wall}, {hx1, hy0, z_wall}, {-1, 0, 0}));
  append(wall, quad_mesh({hx0, hy0, zb}, {hx1, hy0, zb}, {hx1, hy0, z_wall}, {hx0, hy0, z_wall}, {0, 1, 0}));
  append(wall, quad_mesh({hx0, hy1, zb}, {hx1, hy1, zb}, {hx1, hy1, z_wall}, {hx0, hy1, z_wall}, {0, -1, 0}));
  return wall;
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
  // Everything but the far wall, whose triangles lie wholly in its plane; that wall is
  // built again 3 cm further back, with a recess.
  Mesh room;
  room.positions = proxy.positions;
  room.normals = proxy.normals;
  const auto [lo, hi] = proxy.bounds();
  const float far_z = lo.z;
  for (std::size_t t = 0; t + 2 < proxy.indices.size(); t += 3) {
    bool on_far_wall = true;
    for (int k = 0; k < 3; ++k) on_far_wall = on_far_wall && proxy.positions[proxy.indices[t + k]].z < far_z + 1e-4f;
    if (!on_far_wall) room.indices.insert(room.indices.end(), proxy.indices.begin() + t, proxy.indices.begin() + t + 3);
  }
  for (glm::vec3& p : room.positions)
    if (p.z < far_z + 1e-4f) p.z -= 0.03f;
  append(room, wall_with_recess(far_z - 0.03f, lo.x, hi.x, lo.y, hi.y, -1.4f, -0.4f, 0.15f, 0.75f, 0.2f));
  append(room, box_mesh({-3.0f, 0.0f, -1.3f}, {-2.55f, 1.1f, -0.3f}));  // cabinet
  append(room, box_mesh({-0.9f, 0.0f, -0.9f}, {-0.5f, 0.25f, -0.5f}));  // a box on the floor
  append(room, box_mesh({-1.7f, 0.45f, -0.2f}, {-1.0f, 0.49f, 0.4f}));  // low table top
  for (const glm::vec2 leg :
       {glm::vec2(-1.65f, -0.15f), glm::vec2(-1.1f, -0.15f), glm::vec2(-1.65f, 0.3f), glm::vec2(-1.1f, 0.3f)})
    append(room, box_mesh({leg.x, 0.0f, leg.y}, {leg.x + 0.05f, 0.45f, leg.y + 0.05f}));
  return room;
}

}  // namespace lumar::sim
