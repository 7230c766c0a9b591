#include "taiga/backend/pose_factor.hpp"

#include <Eigen/Cholesky>

namespace taiga::backend {

PoseFactor::PoseFactor(const lie::SE3& T_world_body_measured, const lie::Matrix6& covariance)
    : T_measured_world_(T_world_body_measured.inverse()),
      sqrt_information_(Eigen::LLT<lie::Matrix6>(covariance.inverse()).matrixL().transpose()) {}

bool PoseFactor::Evaluate(double const* const* parameters, double* residuals,
                          double** jacobians) const {
  StateBlocks state;
  std::copy(parameters[0], parameters[0] + kPoseSize, state.pose.begin());
  const lie::SE3 T_world_body = state.T_world_body();
  const lie::Vector6 r = (T_measured_world_ * T_world_body).Log();
  Eigen::Map<lie::Vector6>{residuals} = sqrt_information_ * r;
  if (jacobians && jacobians[0]) {
    // The pose tangent's dp is T Exp([R^T dp; 0]) and its dtheta is T Exp([0; dtheta]), so
    // dr/d[dp, dtheta] = Jr^-1(r) * blockdiag(R^T, I).
    lie::Matrix6 to_se3_tangent = lie::Matrix6::Identity();
    to_se3_tangent.topLeftCorner<3, 3>() = T_world_body.rotation().inverse().matrix();
    Eigen::Map<Eigen::Matrix<double, 6, kPoseSize, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.leftCols<6>() = sqrt_information_ * lie::SE3::rightJacobianInverse(r) * to_se3_tangent;
  }
  return true;
}

}  // namespace taiga::backend
