#include "taiga/backend/imu_factor.hpp"

#include <Eigen/Cholesky>

#include "taiga/backend/sqrt_information.hpp"

namespace taiga::backend {
namespace {

using Matrix3 = Eigen::Matrix3d;
using Vector3 = Eigen::Vector3d;
using RowMajorJacobian15x7 = Eigen::Matrix<double, 15, kPoseSize, Eigen::RowMajor>;
using RowMajorJacobian15x9 = Eigen::Matrix<double, 15, kMotionSize, Eigen::RowMajor>;

struct Unpacked {
  imu::NavState state;
  imu::ImuBias bias;
};

Unpacked unpack(const double* pose, const double* motion) {
  StateBlocks blocks;
  std::copy(pose, pose + kPoseSize, blocks.pose.begin());
  std::copy(motion, motion + kMotionSize, blocks.motion.begin());
  return {blocks.navState(), blocks.bias()};
}

}  // namespace

ImuFactor::ImuFactor(imu::Preintegrator preintegrated, const Eigen::Vector3d& gravity_nominal)
    : preintegrated_(std::move(preintegrated)), gravity_nominal_(gravity_nominal) {
  const double dt = preintegrated_.deltaTime();
  const imu::ImuNoise& noise = preintegrated_.noise();
  covariance_.setZero();
  covariance_.topLeftCorner<9, 9>() = preintegrated_.covariance();
  covariance_.block<3, 3>(9, 9) =
      Matrix3::Identity() * noise.accel_bias_random_walk * noise.accel_bias_random_walk * dt;
  covariance_.block<3, 3>(12, 12) =
      Matrix3::Identity() * noise.gyro_bias_random_walk * noise.gyro_bias_random_walk * dt;
  sqrt_information_ = sqrtInformation<15>(covariance_);
}

Vector15 ImuFactor::rawResidual(const StateBlocks& i, const StateBlocks& j) const {
  Vector15 r;
  r.head<9>() = preintegrated_.residual(i.navState(), j.navState(), i.bias(), gravity_nominal_);
  r.segment<3>(9) = j.bias().accel_mps2 - i.bias().accel_mps2;
  r.segment<3>(12) = j.bias().gyro_radps - i.bias().gyro_radps;
  return r;
}

bool ImuFactor::Evaluate(double const* const* parameters, double* residuals,
                         double** jacobians) const {
  const Unpacked i = unpack(parameters[0], parameters[1]);
  const Unpacked j = unpack(parameters[2], parameters[3]);
  const double dt = preintegrated_.deltaTime();
  const imu::ImuBias& bias_hat = preintegrated_.biasHat();
  Eigen::Matrix<double, 3, kTiltSize> dg_dtilt;
  const Vector3 gravity_world =
      gravityFromTilt(parameters[4], gravity_nominal_, jacobians ? &dg_dtilt : nullptr);

  Vector15 r;
  r.head<9>() = preintegrated_.residual(i.state, j.state, i.bias, gravity_world);
  r.segment<3>(9) = j.bias.accel_mps2 - i.bias.accel_mps2;
  r.segment<3>(12) = j.bias.gyro_radps - i.bias.gyro_radps;
  Eigen::Map<Vector15>{residuals} = sqrt_information_ * r;
  if (!jacobians) return true;

  // Tangent Jacobians ([Forster] Appendix C, with dp added in the world frame).
  const Matrix3 R_i_T = i.state.R_world_body.inverse().matrix();
  const Vector3 r_R = r.head<3>();
  const Matrix3 Jr_inv = lie::SO3::rightJacobianInverse(r_R);
  const Vector3 dv_world = j.state.v_world - i.state.v_world - gravity_world * dt;
  const Vector3 dp_world =
      j.state.p_world - i.state.p_world - i.state.v_world * dt - 0.5 * gravity_world * dt * dt;
  const Vector3 dbg = i.bias.gyro_radps - bias_hat.gyro_radps;
  const Matrix3 dR_dbg_corrected = -Jr_inv * lie::SO3::Exp(r_R).inverse().matrix() *
                                   lie::SO3::rightJacobian(preintegrated_.dR_dbg() * dbg) *
                                   preintegrated_.dR_dbg();

  if (jacobians[0]) {  // pose_i: [dp_i, dtheta_i]
    RowMajorJacobian15x7 J = RowMajorJacobian15x7::Zero();
    J.block<3, 3>(0, 3) =
        -Jr_inv * (j.state.R_world_body.inverse() * i.state.R_world_body).matrix();
    J.block<3, 3>(3, 3) = lie::hat(R_i_T * dv_world);
    J.block<3, 3>(6, 0) = -R_i_T;
    J.block<3, 3>(6, 3) = lie::hat(R_i_T * dp_world);
    Eigen::Map<RowMajorJacobian15x7>{jacobians[0]} = sqrt_information_ * J;
  }
  if (jacobians[1]) {  // motion_i: [dv_i, dba_i, dbg_i]
    RowMajorJacobian15x9 J = RowMajorJacobian15x9::Zero();
    J.block<3, 3>(0, 6) = dR_dbg_corrected;
    J.block<3, 3>(3, 0) = -R_i_T;
    J.block<3, 3>(3, 3) = -preintegrated_.dV_dba();
    J.block<3, 3>(3, 6) = -preintegrated_.dV_dbg();
    J.block<3, 3>(6, 0) = -R_i_T * dt;
    J.block<3, 3>(6, 3) = -preintegrated_.dP_dba();
    J.block<3, 3>(6, 6) = -preintegrated_.dP_dbg();
    J.block<3, 3>(9, 3) = -Matrix3::Identity();
    J.block<3, 3>(12, 6) = -Matrix3::Identity();
    Eigen::Map<RowMajorJacobian15x9>{jacobians[1]} = sqrt_information_ * J;
  }
  if (jacobians[2]) {  // pose_j
    RowMajorJacobian15x7 J = RowMajorJacobian15x7::Zero();
    J.block<3, 3>(0, 3) = Jr_inv;
    J.block<3, 3>(6, 0) = R_i_T;
    Eigen::Map<RowMajorJacobian15x7>{jacobians[2]} = sqrt_information_ * J;
  }
  if (jacobians[3]) {  // motion_j
    RowMajorJacobian15x9 J = RowMajorJacobian15x9::Zero();
    J.block<3, 3>(3, 0) = R_i_T;
    J.block<3, 3>(9, 3) = Matrix3::Identity();
    J.block<3, 3>(12, 6) = Matrix3::Identity();
    Eigen::Map<RowMajorJacobian15x9>{jacobians[3]} = sqrt_information_ * J;
  }
  if (jacobians[4]) {  // tilt: r_v and r_p move with -R_i^T g dt and -R_i^T g dt^2 / 2
    Eigen::Matrix<double, 15, kTiltSize, Eigen::RowMajor> J =
        Eigen::Matrix<double, 15, kTiltSize, Eigen::RowMajor>::Zero();
    J.block<3, kTiltSize>(3, 0) = -R_i_T * dg_dtilt * dt;
    J.block<3, kTiltSize>(6, 0) = -0.5 * R_i_T * dg_dtilt * dt * dt;
    Eigen::Map<Eigen::Matrix<double, 15, kTiltSize, Eigen::RowMajor>>{jacobians[4]} =
        sqrt_information_ * J;
  }
  return true;
}

}  // namespace taiga::backend
