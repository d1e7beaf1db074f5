#pragma once
// The CSV dialect of recordings: comma-separated, no quoting, '\n' line ends,
// numbers written so that they read back bit-exactly. A final line without '\n'
// is a write cut short by a crash and is ignored.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace lumar::capture::csv {

void append_int(std::string& out, std::int64_t value);
// Shortest text that parses back to exactly `value` (std::to_chars).
void append_double(std::string& out, double value);

// The whole file; InputError naming it when it is missing or unreadable.
std::string read_file(const std::filesystem::path& path);

// One data row; accessors throw InputError "<file>:<line>: ..." on a bad field.
class Row {
 public:
  Row(const std::filesystem::path& file, std::size_t line, std::vector<std::string_view> fields)
      : file_(file), line_(line), fields_(std::move(fields)) {}
  std::int64_t integer(std::size_t column) const;
  int small_integer(std::size_t column) const;  // fits an int
  double real(std::size_t column) const;        // finite
  [[noreturn]] void fail(const std::string& what) const;

 private:
  const std::filesystem::path& file_;
  std::size_t line_;
  std::vector<std::string_view> fields_;
};

// Calls `fn` for each complete row after the header. Throws InputError naming the
// file and line for a wrong header or a row with a wrong field count. A file with
// no complete line (not even the header) has no rows.
void for_each_row(const std::filesystem::path& path, std::string_view header, std::size_t columns,
                  const std::function<void(const Row&)>& fn);

}  // namespace lumar::capture::csv
