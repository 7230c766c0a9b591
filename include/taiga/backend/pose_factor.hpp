#pragma once
// An absolute pose measurement of one state, e.g. registration of the scan to the local map
// (the lidar factor of thesis Eq. 36): residual r = Log(T_measured^-1 T_world_body) in the SE(3)
// tangent [rho; theta] of lie/ (body frame), whitened by the measurement's covariance in that
// tangent. Parameter block: pose (7); see state_blocks.hpp.

#include <ceres/sized_cost_function.h>

#include "taiga/backend/state_blocks.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::backend {

class PoseFactor final : public ceres::SizedCostFunction<6, kPoseSize> {
 public:
  /// `covariance` (6x6, symmetric positive definite) in the tangent [rho (m); theta (rad)] at
  /// T_world_body_measured.
  PoseFactor(const lie::SE3& T_world_body_measured, const lie::Matrix6& covariance);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  lie::SE3 T_measured_world_;  ///< inverse of the measurement
  lie::Matrix6 sqrt_information_;
};

}  // namespace taiga::backend
