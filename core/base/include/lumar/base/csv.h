#pragma once
// The project's one CSV reader and writer, for every CSV it reads: recordings' logs,
// query points, image poses, trajectories. Comma-separated, no quoting, blanks around a
// field ignored, blank lines skipped. The first line is a header, and readers ask for
// columns by name, so columns may come in any order. Numbers are written so that they
// read back bit-exactly. Errors are one InputError "<file>:<line>: ...".
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace lumar::csv {

void append_int(std::string& out, std::int64_t value);
// Shortest text that parses back to exactly `value` (std::to_chars).
void append_double(std::string& out, double value);

// The columns a reader wants.
struct Columns {
  std::vector<std::string> required;
  std::vector<std::string> optional = {};
  bool others_allowed = true;  // false: an unknown column is an error (a typo would be ignored)
};

// How a final line without '\n' is taken.
enum class LastLine {
  kRead,        // a file written by hand
  kIgnoreTorn,  // a log appended line by line: a write cut short by a crash
};

// One data row; accessors take a column's name and throw InputError naming the file,
// line and column on a bad field.
class Row {
 public:
  bool has(std::string_view column) const;  // the header names it
  std::string_view text(std::string_view column) const;
  std::int64_t integer(std::string_view column) const;
  int small_integer(std::string_view column) const;  // fits an int
  double real(std::string_view column) const;        // finite
  std::size_t line() const { return line_; }
  [[noreturn]] void fail(const std::string& what) const;

 private:
  friend void for_each_row(const std::filesystem::path&, std::string_view, const Columns&, LastLine,
                           const std::function<void(const Row&)>&);
  Row(const std::filesystem::path& file, const std::vector<std::string_view>& header) : file_(file), header_(header) {}
  std::size_t column(std::string_view name) const;
  const std::filesystem::path& file_;
  const std::vector<std::string_view>& header_;
  std::vector<std::string_view> fields_;
  std::size_t line_ = 0;
};

// Calls `fn` for each row after the header of `text`, the contents of `file`. InputError
// naming the file and line for a header without a required column, with an unknown
// column (when not allowed) or a repeated one, or a row whose field count differs from
// the header's. An empty text has no header: an error for LastLine::kRead, no rows for
// kIgnoreTorn (a log whose writer died before its first line).
void for_each_row(const std::filesystem::path& file, std::string_view text, const Columns& columns, LastLine last,
                  const std::function<void(const Row&)>& fn);

}  // namespace lumar::csv
