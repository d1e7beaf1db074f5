#pragma once
// Reading a JSON file, for every JSON the project reads (manifests, sessions, camera
// responses, expectations). Any failure is one InputError naming the file, in words
// without the library's "[json.exception...]" prefix: a syntax error, a number that
// overflows a double ("scale": 1e400), a file that cannot be read.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace lumar {

// `what` names the kind of file in messages, e.g. "scene manifest".
nlohmann::json read_json_file(const std::filesystem::path& file, const std::string& what);
nlohmann::json parse_json_text(const std::string& text, const std::filesystem::path& file);

// A nlohmann::json exception's text without its "[json.exception.type.N] " prefix.
std::string json_error_text(const std::exception& e);

}  // namespace lumar
