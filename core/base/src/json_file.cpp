#include "lumar/base/json_file.h"

#include "lumar/base/error.h"
#include "lumar/base/input_file.h"

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
  return parse_json_text(read_input_file(file, what), file);
}

}  // namespace lumar
