#pragma once
// A PLY header's element counts against the bytes that follow it. assimp trusts the
// counts: a 198-byte ASCII file that declares 10^9 vertices made it allocate without end.
#include <filesystem>

namespace lumar {

// InputError naming the file when a declared element cannot fit in what follows the
// header (at least two bytes per ASCII value, the exact size per binary value, the count
// of a binary list), or when the header is not PLY. Files that are not PLY are left alone.
void check_ply_sizes(const std::filesystem::path& path);

}  // namespace lumar
