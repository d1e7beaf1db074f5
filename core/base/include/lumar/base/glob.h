#pragma once
// File name patterns, one rule for every command: glob(3)'s (*, ?, character classes
// such as [0-9] or [abc]), and the matches in natural order (frame-2 before frame-10).
#include <filesystem>
#include <string>
#include <vector>

namespace lumar {

// Whether `text` holds a pattern character (*, ? or [).
bool is_glob_pattern(const std::string& text);

// The regular files `pattern` matches, in natural order; empty when none does. Throws
// InputError naming the pattern when a folder in it cannot be read.
std::vector<std::filesystem::path> glob_files(const std::string& pattern);

// a < b in natural order: runs of digits compare as numbers ("f2" < "f10").
bool natural_less(const std::string& a, const std::string& b);

}  // namespace lumar
