#pragma once
// Receivers: the real surfaces that shadows fall on, as a mesh of uniformly spaced
// vertices (per-vertex results, interpolated between them), so the shadow's detail does
// not depend on where the object stands.
#include <vector>

#include "lumar/lighting/ray_scene.h"
#include "lumar/scene/mesh.h"
#include "lumar/scene/scene.h"

namespace lumar {

// A uniform grid over each box's two longest axes, dropped onto the proxy along the
// third (thinnest) axis, from the box's upper side (+Y for a floor: the side a
// horizontal surface faces). Grid points that miss the proxy inside the box are left
// out, with the triangles that use them. Spacing: about `target_vertices` in total.
Mesh build_receivers(const RayScene& proxy, const std::vector<SceneBox>& regions, int target_vertices);

// The default receiver region: the room's floor (lowest horizontal level of the proxy)
// under the movement box, widened by `margin` metres on each side, within the room.
std::vector<SceneBox> default_receiver_regions(const Scene& scene, const Mesh& room_world, double margin = 0.5);

}  // namespace lumar
