#pragma once
// Saving a scene someone edited (objects placed, added, removed, recoloured, another
// lighting method): the manifest it was read from, with its objects and lighting method
// rewritten and everything else kept as it was (room, map, lighting, shadows, and each object's keys the editor does not change,
// such as an animated object's path). Relative paths are rewritten against the new
// manifest's folder, so the copy may live anywhere.
#include <filesystem>

#include "lumar/scene/scene.h"

namespace lumar {

// Writes `scene` to `out` atomically (a crash leaves the old file or the new one). Each
// object is written with its final placement, T_world_model: "pose" as translation,
// rotation_wxyz and scale (T_world_model must be a rotation, a uniform scale and a
// translation), so that reading the file back gives the same matrix to double
// precision. An object whose `path` is not empty keeps the source's "pose" and "path"
// (the keys are read against that pose), T_world_model aside. InputError when the
// source manifest cannot be read, RuntimeError when `out` cannot be written.
void save_scene(const Scene& scene, const std::filesystem::path& out);

}  // namespace lumar
