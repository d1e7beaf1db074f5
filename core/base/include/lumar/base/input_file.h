#pragma once
// Opening a file the user named. Every reader goes through here, so that a missing
// file, a directory, a device or a pipe are each told apart in one line, rather than all
// reported as "not found" (or a read of /dev/zero that never ends).
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

namespace lumar {

// Why `file` cannot be read as a file, in words ("not found", "is a directory, not a
// file", "is a device or a pipe, not a file", "cannot be read; check its permissions"),
// or nothing when it can.
std::optional<std::string> input_file_problem(const std::filesystem::path& file);

// InputError "<file>: <what> <problem>; check the path" when input_file_problem says one.
// `what` names the kind of file, e.g. "scene manifest".
void check_input_file(const std::filesystem::path& file, const std::string& what);

// The whole file after check_input_file. InputError for a read error or a file larger
// than `max_bytes` (text inputs are small; a 4 GB "CSV" is a mistake).
std::string read_input_file(const std::filesystem::path& file, const std::string& what,
                            std::size_t max_bytes = std::size_t(1) << 30);

// The name's extension in lower case (".exr" for "MAP.EXR"), for choosing a reader by name.
std::string lower_case_extension(const std::filesystem::path& file);

}  // namespace lumar
