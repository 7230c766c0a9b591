#include "taiga/backend/position_factor.hpp"

#include <Eigen/Cholesky>

#include "taiga/backend/sqrt_information.hpp"

namespace taiga::backend {

PositionFactor::PositionFactor(const Eigen::Vector3d& p_world_measured,
                               const Eigen::Matrix3d& covariance)
    : p_world_measured_(p_world_measured), sqrt_information_(sqrtInformation<3>(covariance)) {}

bool PositionFactor::Evaluate(double const* const* parameters, double* residuals,
                              double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> p_world(parameters[0]);
  Eigen::Map<Eigen::Vector3d>{residuals} = sqrt_information_ * (p_world - p_world_measured_);
  if (jacobians && jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 3, kPoseSize, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.leftCols<3>() = sqrt_information_;  // dp is added to p in the world frame
  }
  return true;
}

}  // namespace taiga::backend
