#pragma once
// A Gaussian prior on one whole odometry state (pose, velocity, biases) and the odom frame's
// tilt: what the fixed-lag smoother keeps of the states it drops. Residual (17) =
// sqrt_information * [p - p0; Log(R0^T R); v - v0; ba - ba0; bg - bg0; tilt - tilt0], in the
// tangent order of state_blocks.hpp. Parameter blocks: pose (7), motion (9), tilt (2).

#include <ceres/sized_cost_function.h>

#include "taiga/backend/imu_factor.hpp"
#include "taiga/backend/state_blocks.hpp"

namespace taiga::backend {

class StatePrior final
    : public ceres::SizedCostFunction<15 + kTiltSize, kPoseSize, kMotionSize, kTiltSize> {
 public:
  static constexpr int kSize = 15 + kTiltSize;
  using Covariance = Eigen::Matrix<double, kSize, kSize>;
  using Tilt = Eigen::Matrix<double, kTiltSize, 1>;
  /// `covariance` in the tangent order [dp; dtheta; dv; dba; dbg; dtilt].
  StatePrior(const StateBlocks& mean, const Tilt& tilt, const Covariance& covariance);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  StateBlocks mean_;
  Tilt tilt_;
  Covariance sqrt_information_;
};

}  // namespace taiga::backend
