#pragma once
// Conversions between double seconds and ROS times. Internal to the io module.

#include <ros/time.h>

#include <cmath>
#include <cstdint>

#include "taiga/core/errors.hpp"

namespace taiga::io::detail {

inline double toSeconds(const ros::Time& t) { return t.sec + 1e-9 * t.nsec; }

/// Nearest ROS time; ROS times are unsigned 32-bit seconds, so t_s must lie in (0, 2^32) s.
inline ros::Time toRosTime(double t_s) {
  if (!(t_s > 0.0 && t_s < 4294967295.0)) {
    throw InputError("a ROS time must lie between 0 and 2^32 s (got " + std::to_string(t_s) + " s)");
  }
  const double whole = std::floor(t_s);
  auto nsec = static_cast<std::int64_t>(std::llround((t_s - whole) * 1e9));
  auto sec = static_cast<std::uint32_t>(whole);
  if (nsec >= 1000000000) {
    nsec -= 1000000000;
    ++sec;
  }
  return ros::Time(sec, static_cast<std::uint32_t>(nsec));
}

}  // namespace taiga::io::detail
