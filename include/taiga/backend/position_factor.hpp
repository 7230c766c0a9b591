#pragma once
// An absolute position measurement of one pose (e.g. a GNSS fix in the world frame, thesis
// Eq. 43): residual r = p_world - p_measured, whitened by the measurement's covariance.
// Parameter block: pose (7); see state_blocks.hpp (its dp is the world-frame position change).

#include <ceres/sized_cost_function.h>

#include "taiga/backend/state_blocks.hpp"

namespace taiga::backend {

class PositionFactor final : public ceres::SizedCostFunction<3, kPoseSize> {
 public:
  PositionFactor(const Eigen::Vector3d& p_world_measured, const Eigen::Matrix3d& covariance);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d p_world_measured_;
  Eigen::Matrix3d sqrt_information_;
};

}  // namespace taiga::backend
