#pragma once
// Plain binary files for the lighting library's caches (the irradiance volume, the shadow
// lines): values and vectors of trivially copyable types, in this machine's byte order,
// and the FNV-1a hash their cache keys are made of. A truncated or corrupt file is an
// InputError naming it and saying to delete it, never a crash.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "lumar/base/error.h"

namespace lumar {

struct BinaryWriter {
  std::ofstream out;
  template <class T>
  void value(const T& v) {
    out.write(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    value(std::uint64_t(v.size()));
    out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
  }
};

struct BinaryReader {
  std::ifstream in;
  std::string name;  // the file
  std::string what;  // what it holds, e.g. "irradiance volume"

  // Opens `file` and checks that it starts with `magic` (a format and its version).
  BinaryReader(const std::filesystem::path& file, std::string holds, const char (&magic)[8])
      : in(file, std::ios::binary), name(file.string()), what(std::move(holds)) {
    if (!in) throw InputError(name + ": " + what + " file not found");
    char start[8] = {};
    in.read(start, sizeof(start));
    if (!in || std::memcmp(start, magic, sizeof(start)) != 0)
      throw InputError(name + ": not a Lumar " + what + " file (or an older version); delete it to rebuild");
  }
  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(name + ": " + what + " file is " + problem + "; delete it to rebuild");
  }
  template <class T>
  void value(T& v) {
    in.read(reinterpret_cast<char*>(&v), sizeof(T));
    if (!in) fail("truncated");
  }
  template <class T>
  void vector(std::vector<T>& v) {
    std::uint64_t n = 0;
    value(n);
    if (n > (std::uint64_t(1) << 32)) fail("corrupt");
    v.resize(std::size_t(n));
    in.read(reinterpret_cast<char*>(v.data()), std::streamsize(n * sizeof(T)));
    if (!in) fail("truncated");
  }
};

// FNV-1a, 64 bits.
struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  }
  template <class T>
  void value(const T& v) {
    bytes(&v, sizeof(T));
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    value(std::uint64_t(v.size()));
    bytes(v.data(), v.size() * sizeof(T));
  }
};

}  // namespace lumar
