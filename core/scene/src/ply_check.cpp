#include "ply_check.h"

#include <strings.h>
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "lumar/base/error.h"
#include "lumar/base/input_file.h"

namespace lumar {

namespace {

// Bytes of one binary value of a PLY scalar type; 0 when the name is unknown.
int scalar_bytes(const std::string& type) {
  static const std::map<std::string, int> sizes = {{"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},
                                                   {"short", 2}, {"ushort", 2},  {"int16", 2},  {"uint16", 2},
                                                   {"int", 4},   {"uint", 4},    {"int32", 4},  {"uint32", 4},
                                                   {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

bool is_float(const std::string& type) { return type.rfind("float", 0) == 0 || type == "double"; }
bool is_signed(const std::string& type) {
  return type == "char" || type == "short" || type == "int" || type.rfind("int", 0) == 0;
}

struct Property {
  std::string name, type;  // type: the item type of a list
  std::string count_type;  // empty: a scalar
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  std::uint64_t min_bytes() const {  // the least one instance can take
    std::uint64_t n = 0;
    for (const auto& p : properties) n += std::uint64_t(scalar_bytes(p.count_type.empty() ? p.type : p.count_type));
    return n;
  }
};

// The values after the header, read as the header says.
class Body {
 public:
  Body(std::string data, bool ascii, bool big_endian, const std::string& file)
      : data_(std::move(data)), ascii_(ascii), big_(big_endian), file_(file) {}

  // One value of `type`, as a double (exact for every integer type PLY has); false at the end.
  bool next(const std::string& type, double& value) {
    if (ascii_) {
      pos_ = data_.find_first_not_of(" \t\r\n", pos_);
      if (pos_ == std::string::npos) return false;
      const std::size_t end = std::min(data_.find_first_of(" \t\r\n", pos_), data_.size());
      const std::string token = data_.substr(pos_, end - pos_);
      pos_ = end;
      char* stop = nullptr;
      value = std::strtod(token.c_str(), &stop);
      if (stop != token.c_str() + token.size())
        throw InputError(file_ + ": PLY value \"" + token.substr(0, 20) + "\" is not a number; repair or re-export it");
      return true;
    }
    const int n = scalar_bytes(type);
    if (data_.size() - pos_ < std::size_t(n)) return false;
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, std::size_t(n));
    pos_ += std::size_t(n);
    if (big_ != (std::endian::native == std::endian::big)) std::reverse(b, b + n);
    if (is_float(type)) {
      if (n == 4) {
        float f;
        std::memcpy(&f, b, 4);
        value = f;
      } else {
        std::memcpy(&value, b, 8);
      }
    } else {
      std::uint64_t u = 0;
      std::memcpy(&u, b, std::size_t(n));
      if (is_signed(type) && n < 8 && (u >> (8 * n - 1)) & 1) u |= ~std::uint64_t(0) << (8 * n);  // sign-extend
      value = is_signed(type) ? double(std::int64_t(u)) : double(u);
    }
    return true;
  }
  std::size_t remaining() const { return data_.size() - std::min(pos_, data_.size()); }
  bool ascii() const { return ascii_; }

 private:
  std::string data_;
  std::size_t pos_ = 0;
  bool ascii_, big_;
  std::string file_;
};

}  // namespace

void check_ply(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::getline(in, line);
  // assimp takes a .ply name, or "ply" in any case, for PLY: it looped forever on "pLy".
  if (lower_case_extension(path) != ".ply" && strncasecmp(line.c_str(), "ply", 3) != 0) return;
  const std::string name = path.string();
  const auto bad = [&](const std::string& why) { throw InputError(name + ": " + why + "; repair or re-export it"); };
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "ply") bad("not a PLY file (its first line must be \"ply\")");
  std::string format;
  std::vector<Element> elements;
  for (int n = 0;; ++n) {
    if (!std::getline(in, line) || n > 10000) bad("PLY header without end_header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    // assimp reads a name up to a NUL, this check up to a blank: such a name would differ.
    if (std::any_of(line.begin(), line.end(), [](unsigned char c) { return c < 0x20 && c != '\t'; }))
      bad("PLY header line " + std::to_string(n + 2) + " holds a control character");
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "end_header") break;
    if (key == "format") {
      words >> format;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        bad("unknown PLY format '" + format + "'");
    } else if (key == "element") {
      Element e;
      std::string count;
      words >> e.name >> count;
      if (count.empty() || count.find_first_not_of("0123456789") != std::string::npos || count.size() > 19)
        bad("PLY element '" + e.name + "' has no valid count");
      e.count = std::stoull(count);
      elements.push_back(e);
    } else if (key == "property") {
      if (elements.empty()) bad("PLY property before any element");
      Property p;
      words >> p.type;
      if (p.type == "list") {
        words >> p.count_type >> p.type;
        if (!scalar_bytes(p.count_type) || is_float(p.count_type) || !scalar_bytes(p.type))
          bad("PLY list property of an unknown type");
      } else if (!scalar_bytes(p.type)) {
        bad("PLY property of unknown type '" + p.type + "'");
      }
      words >> p.name;
      elements.back().properties.push_back(p);
    } else if (key != "comment" && key != "obj_info") {
      // assimp skips a line it does not know and reads the data with a layout that is not
      // the file's. (A blank line is a key of "".)
      bad("PLY header line " + std::to_string(n + 2) + " is not a header line (\"" + line.substr(0, 40) + "\")");
    }
  }
  if (format.empty()) bad("PLY header without a format line");
  std::uint64_t vertices = 0;
  for (const Element& e : elements)
    if (e.name == "vertex") {
      vertices = e.count;
      for (const char* axis : {"x", "y", "z"})
        if (std::none_of(e.properties.begin(), e.properties.end(), [&](const Property& p) { return p.name == axis; }))
          bad(std::string("PLY vertices have no '") + axis + "' property");
    }

  // Counts against the bytes that follow, before reading anything: at least two bytes per
  // ASCII value (an ASCII file's last value may lack its separator), the exact size of a
  // binary one. Each term is capped by the file's size first, so overflow cannot hide a lie.
  const bool ascii = format == "ascii";
  std::ostringstream rest;
  rest << in.rdbuf();
  Body body(std::move(rest).str(), ascii, format == "binary_big_endian", name);
  const std::uint64_t after = body.remaining() + (ascii ? 1 : 0);
  std::uint64_t need = 0;
  for (const Element& e : elements) {
    const std::uint64_t each = ascii ? 2 * e.properties.size() : e.min_bytes();
    if (each > 0 && e.count > after / each)
      bad("PLY header declares " + std::to_string(e.count) + " " + e.name + " elements, more than the " +
          std::to_string(after) + " bytes after the header can hold");
    need += e.count * each;
  }
  if (need > after)
    bad("PLY header declares elements needing at least " + std::to_string(need) + " bytes, but only " +
        std::to_string(after) + " follow the header");

  // The data itself: every value present, every list within the file, every face's
  // vertex indices within the vertices.
  for (const Element& e : elements) {
    const bool faces = e.name == "face";
    for (std::uint64_t i = 0; i < e.count; ++i)
      for (const Property& p : e.properties) {
        const auto ends = [&] {
          bad("PLY data ends in " + e.name + " " + std::to_string(i) + " of " + std::to_string(e.count));
        };
        double value = 0;
        if (p.count_type.empty()) {
          if (!body.next(p.type, value)) ends();
          continue;
        }
        if (!body.next(p.count_type, value)) ends();
        const std::uint64_t least_bytes = ascii ? 1 : std::uint64_t(scalar_bytes(p.type));
        if (value < 0 || value > double(body.remaining() / least_bytes + 1))
          bad("PLY " + e.name + " " + std::to_string(i) + " has a list of " + std::to_string(std::int64_t(value)) +
              " values, more than the file holds");
        const bool indices = faces && (p.name == "vertex_indices" || p.name == "vertex_index");
        // assimp's triangulation asserts (aborts) on a face of fewer than three vertices.
        if (indices && value < 3)
          bad("PLY face " + std::to_string(i) + " has " + std::to_string(std::int64_t(value)) +
              " vertices; a face needs at least 3");
        for (auto k = std::uint64_t(value); k > 0; --k) {
          double index = 0;
          if (!body.next(p.type, index)) ends();
          if (indices && !(index >= 0 && index < double(vertices)))
            bad("PLY face " + std::to_string(i) + " names vertex " + std::to_string(std::int64_t(index)) + " of " +
                std::to_string(vertices));
        }
      }
  }
}

}  // namespace lumar
