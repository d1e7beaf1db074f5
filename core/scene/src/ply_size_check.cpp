#include "ply_size_check.h"

#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "lumar/base/error.h"

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

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::uint64_t min_bytes = 0;  // the least one instance can take
};

}  // namespace

void check_ply_sizes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line.substr(0, 3) != "ply") return;
  const std::string name = path.string();
  const auto bad = [&](const std::string& why) { throw InputError(name + ": " + why + "; repair or re-export it"); };
  bool ascii = false;
  std::vector<Element> elements;
  for (int n = 0; std::getline(in, line); ++n) {
    if (n > 10000) bad("PLY header without end_header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "end_header") {
      const auto header_end = std::uint64_t(in.tellg());
      const auto size = std::uint64_t(std::filesystem::file_size(path));
      // An ASCII file's last value may lack its separator.
      const std::uint64_t after = (size > header_end ? size - header_end : 0) + (ascii ? 1 : 0);
      std::uint64_t need = 0;
      for (const Element& e : elements) {
        // Overflow cannot hide a lie: each term is capped by the file's size first.
        if (e.min_bytes > 0 && e.count > after / e.min_bytes)
          bad("PLY header declares " + std::to_string(e.count) + " " + e.name + " elements, more than the " +
              std::to_string(after) + " bytes after the header can hold");
        need += e.count * e.min_bytes;
      }
      if (need > after)
        bad("PLY header declares elements needing at least " + std::to_string(need) + " bytes, but only " +
            std::to_string(after) + " follow the header");
      return;
    }
    if (key == "format") {
      std::string format;
      words >> format;
      ascii = format == "ascii";
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
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type;
        if (!scalar_bytes(count_type) || !scalar_bytes(item_type)) bad("PLY list property of an unknown type");
        elements.back().min_bytes += ascii ? 2 : scalar_bytes(count_type);
      } else {
        if (!scalar_bytes(type)) bad("PLY property of unknown type '" + type + "'");
        elements.back().min_bytes += ascii ? 2 : scalar_bytes(type);
      }
    }
  }
  bad("PLY header without end_header");
}

}  // namespace lumar
