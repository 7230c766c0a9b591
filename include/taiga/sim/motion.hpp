#pragma once
// Ground-truth motion of a handheld scanner walked through the forest: a closed loop over the
// terrain (so the walk returns to its start and loop closure can be tested), with speed changes,
// heading swings of a person looking around, gait bob and sway. Everything is an analytic function
// of time, so pose, velocity, acceleration and angular rate are exact at any time and the
// simulated IMU is consistent with the trajectory to machine precision.
//
// Horizontal path c(u) = (Rx cos u + sum_k a_k cos(k u + phi_k), Ry sin u + sum_k b_k sin(k u +
// psi_k)) - c(0), walked with phase u(t) = W t + (s/m) sin(m W t); height follows the smooth
// terrain plus the sensor height and bob; orientation R = Rz(yaw) Ry(pitch) Rx(roll) with yaw =
// path heading + look-around swings.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/sim/scenario.hpp"
#include "taiga/sim/terrain.hpp"

namespace taiga::sim {

struct MotionState {
  double t_s = 0.0;
  lie::SE3 T_world_body;
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();     ///< m/s
  Eigen::Vector3d a_world = Eigen::Vector3d::Zero();     ///< m/s^2 (kinematic, without gravity)
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();  ///< rad/s, in the body frame
};

class WalkingMotion {
 public:
  /// A loop sized so that it is walked once in about 95 % of `duration_s` (at least 25 m long,
  /// at most params.max_loop_length_m; longer recordings repeat it).
  WalkingMotion(const MotionParams& params, double duration_s, std::uint64_t seed, Terrain terrain);

  /// The exact state at time t_s (seconds since the start of the recording; any t_s >= 0).
  MotionState at(double t_s) const;

  /// The walked loop as closely spaced horizontal points (world frame), for keeping it free.
  std::vector<Eigen::Vector2d> loopPolyline(double spacing_m = 0.5) const;
  /// Centre of the loop's bounding square and its half size, m.
  Eigen::Vector2d loopCenter() const;
  double loopHalfExtent_m() const;
  /// Time to walk the loop once, s.
  double loopPeriod_s() const { return period_s_; }

 private:
  /// c(u) and its first and second derivatives with respect to u (before the c(0) offset).
  void curve(double u, Eigen::Vector2d* c, Eigen::Vector2d* dc, Eigen::Vector2d* ddc) const;

  MotionParams params_;
  Terrain terrain_;
  double rx_m_ = 10.0, ry_m_ = 10.0;
  double a_[2]{}, phi_[2]{}, b_[2]{}, psi_[2]{};
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();  ///< c(0)
  double period_s_ = 60.0;
  double omega_ = 0.1;      ///< W, rad/s
  int speed_harmonic_ = 1;  ///< m
  double phases_[6]{};      ///< gait and look-around phases
};

}  // namespace taiga::sim
