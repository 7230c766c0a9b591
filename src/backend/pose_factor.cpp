#include "taiga/backend/pose_factor.hpp"

#include <Eigen/Cholesky>

#include "taiga/backend/sqrt_information.hpp"

namespace taiga::backend {

PoseFactor::PoseFactor(const lie::SE3& T_world_body_measured, const lie::Matrix6& covariance)
    : T_measured_world_(T_world_body_measured.inverse()),
      sqrt_information_(sqrtInformation<6>(covariance)) {}

bool PoseFactor::Evaluate(double const* const* parameters, double* residuals,
                          double** jacobians) const {
  const lie::SE3 T_world_body = poseFromBlock(parameters[0]);
  const lie::Vector6 r = (T_measured_world_ * T_world_body).Log();
  Eigen::Map<lie::Vector6>{residuals} = sqrt_information_ * r;
  if (jacobians && jacobians[0]) {
    // The block's dp and dtheta act on T as the SE(3) right perturbation poseTangentToSe3(T)
    // [dp; dtheta], so dr/d[dp, dtheta] = Jr^-1(r) * poseTangentToSe3(T).
    Eigen::Map<Eigen::Matrix<double, 6, kPoseSize, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.leftCols<6>() =
        sqrt_information_ * lie::SE3::rightJacobianInverse(r) * poseTangentToSe3(T_world_body);
  }
  return true;
}

}  // namespace taiga::backend
