#pragma once
// A PLY file checked before assimp reads it. assimp trusts what a PLY says: a 198-byte
// ASCII file that declared 10^9 vertices made it allocate without end, a garbled header
// line made it read the data with the wrong layout and abort in an assertion, and a face
// naming a vertex that does not exist made it read out of bounds (found by fuzz_mesh).
#include <filesystem>

namespace lumar {

// InputError naming the file when the header is not PLY (an unknown line or format, a
// property of unknown type, vertices without x, y and z), when a declared element cannot
// fit in what follows the header, or when the data does not match the header: it ends
// early, a list is longer than the rest of the file, or a face names a vertex index
// outside 0..vertices-1, or when a file named .ply, or starting with "ply" in any case,
// does not start with the line "ply". Other files are left alone.
void check_ply(const std::filesystem::path& path);

}  // namespace lumar
