#pragma once
// A Gaussian prior on one whole odometry state (pose, velocity, biases): what the fixed-lag
// smoother keeps of the states it drops. Residual (15) = sqrt_information *
// [p - p0; Log(R0^T R); v - v0; ba - ba0; bg - bg0], in the tangent order of state_blocks.hpp.
// Parameter blocks: pose (7), motion (9).

#include <ceres/sized_cost_function.h>

#include "taiga/backend/imu_factor.hpp"
#include "taiga/backend/state_blocks.hpp"

namespace taiga::backend {

class StatePrior final : public ceres::SizedCostFunction<15, kPoseSize, kMotionSize> {
 public:
  /// `covariance` in the tangent order [dp; dtheta; dv; dba; dbg].
  StatePrior(const StateBlocks& mean, const Matrix15& covariance);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  StateBlocks mean_;
  Matrix15 sqrt_information_;
};

}  // namespace taiga::backend
