#pragma once
// The shadow lines on disk: built once per scene and loaded at later starts, like the
// irradiance volume (the same cache folder), so that `lumar overlay` reaches its first
// frame sooner. A file is keyed by a hash of everything the lines depend on: the
// receivers, the emitter samples, the proxy and the options.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "lumar/lighting/shadows/shadow_lines.h"
#include "lumar/scene/mesh.h"

namespace lumar {

// Versioned binary file, written atomically. load: InputError when missing, truncated or
// inconsistent (an index out of range), naming the file.
void save_shadow_lines(const ShadowLines& lines, const std::filesystem::path& file);
ShadowLines load_shadow_lines(const std::filesystem::path& file);

std::uint64_t shadow_lines_key(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                               const Emitters& emitters, const Mesh& proxy_world, const ShadowLineOptions& options);

// build_shadow_lines, or its result loaded from `cache_dir` (empty: the irradiance
// volume's default folder) when a file with the same key is there; a file that does not
// load is rebuilt with a warning. `proxy_world` is the mesh `proxy` was made of.
// `loaded` says which.
ShadowLines cached_shadow_lines(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                                const Emitters& emitters, const RayScene& proxy, const Mesh& proxy_world,
                                const ShadowLineOptions& options = {}, std::filesystem::path cache_dir = {},
                                bool* loaded = nullptr);

}  // namespace lumar
