// The session reader (session_from_json): any bytes give a Session or one InputError,
// and an accepted session survives session_to_json → session_from_json unchanged (up to
// the last bits of its numbers).
#include <algorithm>
#include <cmath>

#include "fuzz_input.h"
#include "lumar/base/error.h"
#include "lumar/base/json_file.h"
#include "lumar/capture/session.h"

namespace {

// Equal up to the last bits of floating-point numbers: reading normalises quaternions,
// and normalising a unit quaternion again may move its last bit.
bool near(const nlohmann::json& a, const nlohmann::json& b) {
  if (a.is_number_float() || b.is_number_float()) {
    if (!a.is_number() || !b.is_number()) return false;
    const double x = a.get<double>(), y = b.get<double>();
    return std::abs(x - y) <= 1e-12 * std::max({1.0, std::abs(x), std::abs(y)});
  }
  if (a.type() != b.type() || a.size() != b.size()) return false;
  if (a.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it)
      if (!b.contains(it.key()) || !near(it.value(), b.at(it.key()))) return false;
    return true;
  }
  if (a.is_array()) {
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!near(a[i], b[i])) return false;
    return true;
  }
  return a == b;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lumar;
  const std::string text(reinterpret_cast<const char*>(data), size);
  capture::Session session;
  try {
    session = capture::session_from_json(parse_json_text(text, "session.json"), "session.json");
  } catch (const InputError&) {
    return 0;
  }
  const nlohmann::json once = capture::session_to_json(session);
  capture::Session again;
  try {
    again = capture::session_from_json(once, "written.json");
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    fuzz::property_failed("a session that was read is refused once written");
  }
  if (!near(capture::session_to_json(again), once)) {
    std::fprintf(stderr, "written: %s\nread back and written again: %s\n", once.dump().c_str(),
                 capture::session_to_json(again).dump().c_str());
    fuzz::property_failed("a session read, written and read again differs");
  }
  return 0;
}
