#include "taiga/backend/relative_pose_factor.hpp"

#include <Eigen/Cholesky>

#include "taiga/backend/sqrt_information.hpp"

namespace taiga::backend {

RelativePoseFactor::RelativePoseFactor(const lie::SE3& T_i_j_measured,
                                       const lie::Matrix6& covariance)
    : T_j_i_measured_(T_i_j_measured.inverse()),
      sqrt_information_(sqrtInformation<6>(covariance)) {}

lie::Vector6 RelativePoseFactor::error(const lie::SE3& T_world_i, const lie::SE3& T_world_j) const {
  return (T_j_i_measured_ * (T_world_i.inverse() * T_world_j)).Log();
}

bool RelativePoseFactor::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const lie::SE3 T_world_i = poseFromBlock(parameters[0]);
  const lie::SE3 T_world_j = poseFromBlock(parameters[1]);
  const lie::SE3 T_i_j = T_world_i.inverse() * T_world_j;
  const lie::Vector6 r = (T_j_i_measured_ * T_i_j).Log();
  Eigen::Map<lie::Vector6>{residuals} = sqrt_information_ * r;
  if (!jacobians) return true;
  const lie::Matrix6 Jr_inv = lie::SE3::rightJacobianInverse(r);
  // E = M T_i^-1 T_j. Right-perturbing T_j by xi gives E Exp(xi): dr/dxi_j = Jr^-1(r).
  // Right-perturbing T_i gives M Exp(-xi) T_i^-1 T_j = E Exp(-Ad(T_j^-1 T_i) xi):
  // dr/dxi_i = -Jr^-1(r) Ad(T_i_j^-1).
  if (jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 6, kPoseSize, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.leftCols<6>() =
        -sqrt_information_ * Jr_inv * T_i_j.inverse().adjoint() * poseTangentToSe3(T_world_i);
  }
  if (jacobians[1]) {
    Eigen::Map<Eigen::Matrix<double, 6, kPoseSize, Eigen::RowMajor>> J(jacobians[1]);
    J.setZero();
    J.leftCols<6>() = sqrt_information_ * Jr_inv * poseTangentToSe3(T_world_j);
  }
  return true;
}

}  // namespace taiga::backend
