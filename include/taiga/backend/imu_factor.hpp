#pragma once
// The preintegrated IMU factor between consecutive odometry states i and j, with the bias random
// walk, after [Forster] (Forster et al., IEEE T-RO 2017; see imu/preintegration.hpp).
//
// Residual (15), whitened by the square-root information:
//   r_R  = Log(dR(bg_i)^T R_i^T R_j)                                   [Forster] Eq. 45
//   r_v  = R_i^T (v_j - v_i - g dt) - dv(ba_i, bg_i)
//   r_p  = R_i^T (p_j - p_i - v_i dt - g dt^2 / 2) - dp(ba_i, bg_i)
//   r_ba = ba_j - ba_i,  r_bg = bg_j - bg_i                             (bias random walk)
// Covariance: the preintegration's noise covariance for [r_R; r_v; r_p] and the random walk's
// sigma^2 dt for the biases.
//
// Here g is the odom frame's gravity: g_nominal turned by the tilt block (state_blocks.hpp,
// gravityFromTilt), held constant unless the odometry estimates the frame's tilt.
//
// Parameter blocks: pose_i (7), motion_i (9), pose_j (7), motion_j (9), tilt (2); see
// state_blocks.hpp.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "taiga/backend/state_blocks.hpp"
#include "taiga/imu/preintegration.hpp"

namespace taiga::backend {

using Vector15 = Eigen::Matrix<double, 15, 1>;
using Matrix15 = Eigen::Matrix<double, 15, 15>;

class ImuFactor final : public ceres::SizedCostFunction<15, kPoseSize, kMotionSize, kPoseSize,
                                                        kMotionSize, kTiltSize> {
 public:
  ImuFactor(imu::Preintegrator preintegrated, const Eigen::Vector3d& gravity_nominal);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  /// The unwhitened residual at a zero tilt, for tests and diagnostics.
  Vector15 rawResidual(const StateBlocks& i, const StateBlocks& j) const;
  const Matrix15& covariance() const { return covariance_; }

 private:
  imu::Preintegrator preintegrated_;
  Eigen::Vector3d gravity_nominal_;
  Matrix15 covariance_;
  Matrix15 sqrt_information_;  ///< L^T with L L^T = covariance^-1
};

}  // namespace taiga::backend
