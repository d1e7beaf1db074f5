#include "lumar/base/json_file.h"

#include <fstream>
#include <sstream>

#include "lumar/base/error.h"

namespace lumar {

std::string json_error_text(const std::exception& e) {
  std::string why = e.what();
  if (why.rfind("[json.exception.", 0) == 0)
    if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
  return why;
}

nlohmann::json parse_json_text(const std::string& text, const std::filesystem::path& file) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": malformed JSON: " + json_error_text(e));
  }
}

nlohmann::json read_json_file(const std::filesystem::path& file, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(file.string() + ": " + what + " not found (or not a file); check the path");
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  if (!in) throw InputError(file.string() + ": cannot read the " + what);
  text << in.rdbuf();
  return parse_json_text(text.str(), file);
}

}  // namespace lumar
