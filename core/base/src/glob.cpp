#include "lumar/base/glob.h"

#include <glob.h>

#include <algorithm>
#include <cctype>
#include <system_error>

#include "lumar/base/error.h"

namespace lumar {

bool is_glob_pattern(const std::string& text) { return text.find_first_of("*?[") != std::string::npos; }

std::vector<std::filesystem::path> glob_files(const std::string& pattern) {
  std::vector<std::filesystem::path> out;
  glob_t g{};
  const int rc = ::glob(pattern.c_str(), GLOB_ERR, nullptr, &g);
  if (rc == 0) {
    std::error_code ec;
    for (std::size_t i = 0; i < g.gl_pathc; ++i)
      if (std::filesystem::is_regular_file(g.gl_pathv[i], ec)) out.emplace_back(g.gl_pathv[i]);
  }
  globfree(&g);
  if (rc == GLOB_ABORTED) throw InputError(pattern + ": cannot read a folder of this pattern; check that it exists");
  if (rc == GLOB_NOSPACE) throw RuntimeError(pattern + ": out of memory while listing the files");
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return natural_less(a.string(), b.string()); });
  return out;
}

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit((unsigned char)a[i]) && std::isdigit((unsigned char)b[j])) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit((unsigned char)a[ie])) ++ie;
      while (je < b.size() && std::isdigit((unsigned char)b[je])) ++je;
      // Compare as numbers without overflow: strip leading zeros, then length, then text.
      std::size_t is = i, js = j;
      while (is + 1 < ie && a[is] == '0') ++is;
      while (js + 1 < je && b[js] == '0') ++js;
      if (ie - is != je - js) return ie - is < je - js;
      const int c = a.compare(is, ie - is, b, js, je - js);
      if (c != 0) return c < 0;
      if (ie - i != je - j) return ie - i < je - j;  // "01" after "1"
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

}  // namespace lumar
