#pragma once
// A room that differs from the proxy the overlay is given, as a real one does: the video
// of an "honest" synthetic recording is rendered from this room, the overlay still uses
// the plain proxy. So aligning the video with the proxy is not exact, and image-aided
// tracking is tested against geometry it does not know.
#include "lumar/scene/mesh.h"

namespace lumar::sim {

// The proxy with its far wall (least z) 3 cm further back and a recess in it (1.0 x 0.6 m,
// 20 cm deep, low, where the orbit sees it), a cabinet against its left wall (least x), and on the floor near the
// sample's figurine, where the orbit looks, a box and a low table on four legs. Boxes
// face outwards. The proxy must be a room whose floor is at y = 0 (the sample room's box)
// with its far wall one rectangle over the room's whole width and height.
Mesh furnished_room(const Mesh& proxy);

// An axis-aligned box with outward faces, four vertices per face for flat normals.
Mesh box_mesh(const glm::vec3& lo, const glm::vec3& hi);

}  // namespace lumar::sim
