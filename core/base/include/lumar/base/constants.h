#pragma once
// Numbers written once for every part of Lumar.
#include <numbers>

namespace lumar {

inline constexpr double kPi = std::numbers::pi;

}  // namespace lumar
