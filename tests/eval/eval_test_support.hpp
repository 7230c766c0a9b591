#pragma once
// Small trajectories with known geometry for the eval tests.

#include <cmath>
#include <numbers>
#include <vector>

#include "taiga/core/trajectory.hpp"

namespace taiga::eval::test {

inline lie::SE3 yawPose(double yaw_rad, const Eigen::Vector3d& t) {
  return {lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), yaw_rad), t};
}

/// A 3D path that no line or plane contains: a helix-like curve of n poses at 10 Hz from t0_s,
/// heading along the curve.
inline std::vector<StampedPose> curvedPath(std::size_t n, double t0_s = 100.0) {
  std::vector<StampedPose> poses;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 0.05 * static_cast<double>(i);
    poses.push_back({t0_s + 0.1 * static_cast<double>(i),
                     yawPose(a + std::numbers::pi / 2,
                             {10.0 * std::cos(a), 10.0 * std::sin(a), 0.5 * std::sin(3.0 * a)})});
  }
  return poses;
}

/// Straight line along x with `step_m` between poses, identity orientation, 10 Hz.
inline std::vector<StampedPose> straightLine(std::size_t n, double step_m) {
  std::vector<StampedPose> poses;
  for (std::size_t i = 0; i < n; ++i)
    poses.push_back({0.1 * static_cast<double>(i),
                     lie::SE3(lie::SO3(), {step_m * static_cast<double>(i), 0.0, 0.0})});
  return poses;
}

inline std::vector<StampedPose> transformed(const lie::SE3& T, const std::vector<StampedPose>& in) {
  std::vector<StampedPose> out;
  for (const StampedPose& p : in) out.push_back({p.t_s, T * p.pose});
  return out;
}

}  // namespace taiga::eval::test
