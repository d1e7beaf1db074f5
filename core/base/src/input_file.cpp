#include "lumar/base/input_file.h"

#include <unistd.h>

#include <cctype>
#include <fstream>
#include <sstream>

#include "lumar/base/error.h"

namespace lumar {
namespace fs = std::filesystem;

std::optional<std::string> input_file_problem(const fs::path& file) {
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (status.type() == fs::file_type::not_found) return "not found";
  if (ec) return "cannot be reached (" + ec.message() + ")";
  if (status.type() == fs::file_type::directory) return "is a directory, not a file";
  if (status.type() != fs::file_type::regular) return "is a device or a pipe, not a file";
  if (::access(file.c_str(), R_OK) != 0) return "cannot be read; check its permissions";
  return std::nullopt;
}

void check_input_file(const fs::path& file, const std::string& what) {
  if (const auto problem = input_file_problem(file))
    throw InputError(file.string() + ": " + what + " " + *problem + "; check the path");
}

std::string read_input_file(const fs::path& file, const std::string& what, std::size_t max_bytes) {
  check_input_file(file, what);
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (!ec && size > max_bytes)
    throw InputError(file.string() + ": " + what + " of " + std::to_string(size) + " bytes is larger than the " +
                     std::to_string(max_bytes) + " bytes allowed; is it the right file?");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": " + what + " cannot be opened; check its permissions");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(file.string() + ": read error in the " + what + "; check the disk");
  return std::move(text).str();
}

std::string lower_case_extension(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

}  // namespace lumar
