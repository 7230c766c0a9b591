#pragma once
// A relative pose measurement between two poses, e.g. the odometry between two keyframes or a
// loop closure: residual r = Log(T_ij_measured^-1 T_world_i^-1 T_world_j) in the SE(3) tangent
// [rho; theta] of lie/ (frame j), whitened by the measurement's covariance in that tangent.
// Parameter blocks: pose i (7), pose j (7); see state_blocks.hpp.

#include <ceres/sized_cost_function.h>

#include "taiga/backend/state_blocks.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::backend {

class RelativePoseFactor final : public ceres::SizedCostFunction<6, kPoseSize, kPoseSize> {
 public:
  /// `covariance` (6x6, symmetric positive definite) in the tangent [rho (m); theta (rad)] at
  /// T_i_j_measured (right perturbation).
  RelativePoseFactor(const lie::SE3& T_i_j_measured, const lie::Matrix6& covariance);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  /// The unwhitened residual Log(T_ij_measured^-1 T_world_i^-1 T_world_j).
  lie::Vector6 error(const lie::SE3& T_world_i, const lie::SE3& T_world_j) const;

 private:
  lie::SE3 T_j_i_measured_;  ///< inverse of the measurement
  lie::Matrix6 sqrt_information_;
};

}  // namespace taiga::backend
