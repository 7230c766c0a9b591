#include "taiga/backend/state_prior.hpp"

#include <Eigen/Cholesky>

#include "taiga/backend/sqrt_information.hpp"

namespace taiga::backend {

StatePrior::StatePrior(const StateBlocks& mean, const Tilt& tilt, const Covariance& covariance)
    : mean_(mean), tilt_(tilt), sqrt_information_(sqrtInformation<kSize>(covariance)) {}

bool StatePrior::Evaluate(double const* const* parameters, double* residuals,
                          double** jacobians) const {
  StateBlocks state;
  std::copy(parameters[0], parameters[0] + kPoseSize, state.pose.begin());
  std::copy(parameters[1], parameters[1] + kMotionSize, state.motion.begin());
  const imu::NavState x = state.navState();
  const imu::NavState x0 = mean_.navState();
  Eigen::Matrix<double, kSize, 1> r;
  r.segment<3>(0) = x.p_world - x0.p_world;
  r.segment<3>(3) = x.R_world_body.minus(x0.R_world_body);
  r.segment<9>(6) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(state.motion.data()) -
                    Eigen::Map<const Eigen::Matrix<double, 9, 1>>(mean_.motion.data());
  r.tail<kTiltSize>() = Eigen::Map<const Tilt>(parameters[2]) - tilt_;
  Eigen::Map<Eigen::Matrix<double, kSize, 1>>{residuals} = sqrt_information_ * r;
  if (!jacobians) return true;
  if (jacobians[0]) {
    Eigen::Matrix<double, kSize, kPoseSize, Eigen::RowMajor> J =
        Eigen::Matrix<double, kSize, kPoseSize, Eigen::RowMajor>::Zero();
    J.block<3, 3>(0, 0).setIdentity();
    J.block<3, 3>(3, 3) = lie::SO3::rightJacobianInverse(r.segment<3>(3));
    Eigen::Map<Eigen::Matrix<double, kSize, kPoseSize, Eigen::RowMajor>>{jacobians[0]} =
        sqrt_information_ * J;
  }
  if (jacobians[1]) {
    Eigen::Matrix<double, kSize, kMotionSize, Eigen::RowMajor> J =
        Eigen::Matrix<double, kSize, kMotionSize, Eigen::RowMajor>::Zero();
    J.block<9, 9>(6, 0).setIdentity();
    Eigen::Map<Eigen::Matrix<double, kSize, kMotionSize, Eigen::RowMajor>>{jacobians[1]} =
        sqrt_information_ * J;
  }
  if (jacobians[2]) {
    Eigen::Matrix<double, kSize, kTiltSize, Eigen::RowMajor> J =
        Eigen::Matrix<double, kSize, kTiltSize, Eigen::RowMajor>::Zero();
    J.bottomRows<kTiltSize>().setIdentity();
    Eigen::Map<Eigen::Matrix<double, kSize, kTiltSize, Eigen::RowMajor>>{jacobians[2]} =
        sqrt_information_ * J;
  }
  return true;
}

}  // namespace taiga::backend
