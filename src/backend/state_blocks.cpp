#include "taiga/backend/state_blocks.hpp"

#include <Eigen/Core>

namespace taiga::backend {
namespace {

lie::SO3 rotationOf(const double* pose) {
  return lie::SO3(Eigen::Quaterniond(pose[6], pose[3], pose[4], pose[5]));
}

void writeRotation(const lie::SO3& R, double* pose) {
  const Eigen::Quaterniond& q = R.quaternion();
  pose[3] = q.x();
  pose[4] = q.y();
  pose[5] = q.z();
  pose[6] = q.w();
}

}  // namespace

StateBlocks StateBlocks::from(const imu::NavState& state, const imu::ImuBias& bias) {
  StateBlocks blocks;
  Eigen::Map<Eigen::Vector3d>{blocks.pose.data()} = state.p_world;
  writeRotation(state.R_world_body, blocks.pose.data());
  Eigen::Map<Eigen::Vector3d>{blocks.motion.data()} = state.v_world;
  Eigen::Map<Eigen::Vector3d>{blocks.motion.data() + 3} = bias.accel_mps2;
  Eigen::Map<Eigen::Vector3d>{blocks.motion.data() + 6} = bias.gyro_radps;
  return blocks;
}

imu::NavState StateBlocks::navState() const {
  return {rotationOf(pose.data()), Eigen::Map<const Eigen::Vector3d>(pose.data()),
          Eigen::Map<const Eigen::Vector3d>(motion.data())};
}

imu::ImuBias StateBlocks::bias() const {
  return {Eigen::Map<const Eigen::Vector3d>(motion.data() + 3),
          Eigen::Map<const Eigen::Vector3d>(motion.data() + 6)};
}

lie::SE3 StateBlocks::T_world_body() const { return poseFromBlock(pose.data()); }

Eigen::Vector3d gravityFromTilt(const double* tilt, const Eigen::Vector3d& g_nominal,
                                Eigen::Matrix<double, 3, kTiltSize>* d_gravity_d_tilt) {
  // Exactly g_nominal at a zero tilt, so an odometry that does not estimate the tilt is unchanged.
  if (tilt[0] == 0.0 && tilt[1] == 0.0 && !d_gravity_d_tilt) return g_nominal;
  const Eigen::Vector3d phi(tilt[0], tilt[1], 0.0);
  const lie::SO3 R = lie::SO3::Exp(phi);
  if (d_gravity_d_tilt) {
    const Eigen::Matrix3d J = -(R.matrix() * lie::hat(g_nominal) * lie::SO3::rightJacobian(phi));
    *d_gravity_d_tilt = J.leftCols<kTiltSize>();
  }
  return R * g_nominal;
}

lie::SE3 poseFromBlock(const double* pose_block) {
  return lie::SE3(rotationOf(pose_block), Eigen::Map<const Eigen::Vector3d>(pose_block));
}

void writePoseBlock(const lie::SE3& T_world_body, double* pose_block) {
  Eigen::Map<Eigen::Vector3d>{pose_block} = T_world_body.translation();
  writeRotation(T_world_body.rotation(), pose_block);
}

lie::Matrix6 poseTangentToSe3(const lie::SE3& T_world_body) {
  lie::Matrix6 to_se3 = lie::Matrix6::Identity();
  to_se3.topLeftCorner<3, 3>() = T_world_body.rotation().inverse().matrix();
  return to_se3;
}

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  for (int i = 0; i < 3; ++i) x_plus_delta[i] = x[i] + delta[i];
  writeRotation(rotationOf(x) * lie::SO3::Exp(Eigen::Map<const Eigen::Vector3d>(delta + 3)),
                x_plus_delta);
  return true;
}

bool PoseManifold::PlusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, kPoseSize, kPoseTangentSize, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>().setIdentity();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  for (int i = 0; i < 3; ++i) y_minus_x[i] = y[i] - x[i];
  Eigen::Map<Eigen::Vector3d>{y_minus_x + 3} = rotationOf(y).minus(rotationOf(x));
  return true;
}

bool PoseManifold::MinusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, kPoseTangentSize, kPoseSize, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>().setIdentity();
  return true;
}

}  // namespace taiga::backend
