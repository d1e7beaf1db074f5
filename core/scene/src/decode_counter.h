#pragma once
// Counts of scene files decoded, by path (private to scene/; scene_file_decodes()).
#include <filesystem>
#include <map>

namespace lumar {

void count_decode(const std::filesystem::path& file);
std::map<std::filesystem::path, int> decode_counts();

}  // namespace lumar
