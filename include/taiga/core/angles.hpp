#pragma once
// The one place for angle unit constants: multiply degrees by kRadPerDeg to get radians, radians
// by kDegPerRad to get degrees (the name says what one unit of the result is per unit of input).

#include <numbers>

namespace taiga {

inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;

}  // namespace taiga
