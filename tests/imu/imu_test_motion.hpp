#pragma once
// A smooth analytic motion with exact IMU readings, for testing integration against ground truth
// (in the spirit of GTSAM's scenario runner): position and rotation vector are sums of sines, so
// velocity, acceleration and angular rate are known in closed form at any time.

#include <Eigen/Core>
#include <cmath>

#include "taiga/imu/preintegration.hpp"
#include "taiga/lie/so3.hpp"

namespace taiga::imu::test {

inline const Vector3 kGravityWorld(0.0, 0.0, -9.81);

struct WavyMotion {
  /// theta(t): rotation vector of R_world_body, rad.
  static Vector3 theta(double t) {
    return {0.3 * std::sin(0.9 * t), 0.2 * std::cos(0.6 * t), 0.8 * std::sin(0.4 * t)};
  }
  static Vector3 thetaDot(double t) {
    return {0.27 * std::cos(0.9 * t), -0.12 * std::sin(0.6 * t), 0.32 * std::cos(0.4 * t)};
  }
  static Vector3 position(double t) {
    return {2.0 * std::sin(0.5 * t), 1.5 * std::cos(0.7 * t), 0.3 * std::sin(1.1 * t)};
  }
  static Vector3 velocity(double t) {
    return {1.0 * std::cos(0.5 * t), -1.05 * std::sin(0.7 * t), 0.33 * std::cos(1.1 * t)};
  }
  static Vector3 acceleration(double t) {
    return {-0.5 * std::sin(0.5 * t), -0.735 * std::cos(0.7 * t), -0.363 * std::sin(1.1 * t)};
  }

  static NavState state(double t) { return {lie::SO3::Exp(theta(t)), position(t), velocity(t)}; }
  /// Angular rate in the body frame: R(t + dt) = Exp(theta + thetaDot dt) = R(t) Exp(Jr(theta)
  /// thetaDot dt).
  static Vector3 gyro(double t) { return lie::SO3::rightJacobian(theta(t)) * thetaDot(t); }
  /// Specific force in the body frame: R^T (a - g).
  static Vector3 accel(double t) {
    return lie::SO3::Exp(theta(t)).inverse() * (acceleration(t) - kGravityWorld);
  }
};

}  // namespace taiga::imu::test
