#include "lumar/base/csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "lumar/base/error.h"

namespace lumar::csv {

namespace {

std::string_view trimmed(std::string_view s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string_view::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

void split(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  for (std::size_t start = 0;;) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trimmed(line.substr(start, comma == std::string_view::npos ? comma : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

}  // namespace

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

void Row::fail(const std::string& what) const {
  throw InputError(file_.string() + ":" + std::to_string(line_) + ": " + what);
}

std::size_t Row::column(std::string_view name) const {
  const auto it = std::find(header_.begin(), header_.end(), name);
  if (it == header_.end()) fail("no column '" + std::string(name) + "'");  // a reader's mistake, not the file's
  return std::size_t(it - header_.begin());
}

bool Row::has(std::string_view name) const { return std::find(header_.begin(), header_.end(), name) != header_.end(); }

std::string_view Row::text(std::string_view name) const { return fields_[column(name)]; }

std::int64_t Row::integer(std::string_view name) const {
  const std::string_view f = text(name);
  std::int64_t value = 0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), value);
  if (r.ec != std::errc() || r.ptr != f.data() + f.size() || f.empty())
    fail(std::string(name) + " '" + std::string(f) + "' is not an integer");
  return value;
}

int Row::small_integer(std::string_view name) const {
  const std::int64_t v = integer(name);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail(std::string(name) + " " + std::to_string(v) + " is out of range");
  return int(v);
}

double Row::real(std::string_view name) const {
  const std::string_view f = text(name);
  double value = 0;
  const char* first = f.data() + (f.size() > 1 && f[0] == '+' ? 1 : 0);  // from_chars refuses a '+'
  const auto r = std::from_chars(first, f.data() + f.size(), value);
  if (r.ec != std::errc() || r.ptr != f.data() + f.size() || f.empty() || !std::isfinite(value))
    fail(std::string(name) + " '" + std::string(f) + "' is not a finite number");
  return value;
}

void for_each_row(const std::filesystem::path& file, std::string_view text, const Columns& columns, LastLine last,
                  const std::function<void(const Row&)>& fn) {
  const std::string expected = joined(columns.required);
  std::vector<std::string_view> header;
  Row row(file, header);
  std::size_t line = 0;
  for (std::string_view rest = text; !rest.empty();) {
    std::size_t end = rest.find('\n');
    if (end == std::string_view::npos) {
      if (last == LastLine::kIgnoreTorn) break;  // a torn final write, ignored on purpose
      end = rest.size();
    }
    const std::string_view content = rest.substr(0, end);
    rest.remove_prefix(std::min(end + 1, rest.size()));
    ++line;
    row.line_ = line;
    if (line == 1) {
      split(content, header);
      for (std::size_t i = 0; i < header.size(); ++i) {
        const std::string name(header[i]);
        const bool known = std::count(columns.required.begin(), columns.required.end(), name) +
                           std::count(columns.optional.begin(), columns.optional.end(), name);
        if (!known && !columns.others_allowed)
          row.fail("unknown column '" + name + "' in the header; the columns are " + expected +
                   (columns.optional.empty() ? "" : " and optionally " + joined(columns.optional)));
        if (std::find(header.begin(), header.begin() + std::ptrdiff_t(i), header[i]) !=
            header.begin() + std::ptrdiff_t(i))
          row.fail("column '" + name + "' appears twice in the header");
      }
      for (const auto& name : columns.required)
        if (std::find(header.begin(), header.end(), name) == header.end())
          row.fail("the header has no column '" + name + "'; expected a header naming " + expected);
      continue;
    }
    if (trimmed(content).empty()) continue;
    split(content, row.fields_);
    if (row.fields_.size() != header.size())
      row.fail("expected " + std::to_string(header.size()) + " fields like the header, found " +
               std::to_string(row.fields_.size()));
    fn(row);
  }
  if (line == 0 && last == LastLine::kRead)
    throw InputError(file.string() + ": empty; expected a header naming " + expected);
}

}  // namespace lumar::csv
