#include "csv_text.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "lumar/base/error.h"

namespace lumar::capture::csv {

void append_int(std::string& out, std::int64_t value) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, r.ptr);
}

void append_double(std::string& out, double value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, r.ptr);
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (!std::filesystem::exists(path))
      throw InputError(path.string() + ": missing; the recording is incomplete or not a recording");
    throw InputError(path.string() + ": cannot be read; check its permissions");
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path.string() + ": read error; check the disk");
  return std::move(text).str();
}

void Row::fail(const std::string& what) const {
  throw InputError(file_.string() + ":" + std::to_string(line_) + ": " + what +
                   "; the file is corrupt (fix or delete the line)");
}

std::int64_t Row::integer(std::size_t column) const {
  const std::string_view f = fields_.at(column);
  std::int64_t value = 0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), value);
  if (r.ec != std::errc() || r.ptr != f.data() + f.size() || f.empty())
    fail("field " + std::to_string(column + 1) + " \"" + std::string(f) + "\" is not an integer");
  return value;
}

int Row::small_integer(std::size_t column) const {
  const std::int64_t v = integer(column);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail("field " + std::to_string(column + 1) + " is out of range");
  return int(v);
}

double Row::real(std::size_t column) const {
  const std::string_view f = fields_.at(column);
  double value = 0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), value);
  if (r.ec != std::errc() || r.ptr != f.data() + f.size() || f.empty() || !std::isfinite(value))
    fail("field " + std::to_string(column + 1) + " \"" + std::string(f) + "\" is not a finite number");
  return value;
}

void for_each_row(const std::filesystem::path& path, std::string_view header, std::size_t columns,
                  const std::function<void(const Row&)>& fn) {
  const std::string text = read_file(path);
  std::string_view rest = text;
  std::size_t line = 0;
  std::vector<std::string_view> fields;
  for (std::size_t end; (end = rest.find('\n')) != std::string_view::npos; rest.remove_prefix(end + 1)) {
    const std::string_view content = rest.substr(0, end);
    ++line;
    if (line == 1) {
      if (content != header)
        throw InputError(path.string() + ":1: expected the header \"" + std::string(header) +
                         "\"; this is not a recording's " + path.filename().string());
      continue;
    }
    fields.clear();
    for (std::size_t start = 0;;) {
      const std::size_t comma = content.find(',', start);
      fields.push_back(content.substr(start, comma - start));
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    const Row row(path, line, fields);
    if (fields.size() != columns)
      row.fail("expected " + std::to_string(columns) + " fields, found " + std::to_string(fields.size()));
    fn(row);
  }
  // Whatever is left has no '\n': a torn final write, ignored on purpose.
}

}  // namespace lumar::capture::csv
