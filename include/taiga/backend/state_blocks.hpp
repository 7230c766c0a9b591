#pragma once
// How the odometry states live in Ceres parameter blocks.
//
//   pose block   (7): [p_world (3); q_world_body as x, y, z, w (4)]      -> T_world_body
//   motion block (9): [v_world (3); accel bias (3); gyro bias (3)]
//
// The pose block's tangent is [dp (3, world frame, added to p); dtheta (3, body frame, right
// perturbation R Exp(dtheta))]. Factors write their Jacobians with respect to this tangent into
// the first 6 columns of the 7 ambient columns (the 7th stays zero), and PoseManifold's
// PlusJacobian is [I6; 0], so Ceres' product of the two is the tangent Jacobian itself.

#include <ceres/manifold.h>

#include <array>

#include "taiga/imu/preintegration.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::backend {

constexpr int kPoseSize = 7;
constexpr int kPoseTangentSize = 6;
constexpr int kMotionSize = 9;
/// The odom frame's tilt against gravity (2): [theta_x; theta_y] rad, gravity in the odom frame
/// = Exp([theta_x, theta_y, 0]) g_nominal (gravityFromTilt). Zero: the frame as levelled.
constexpr int kTiltSize = 2;

/// Gravity in the world frame for a tilt block, and its Jacobian (3 x 2) with respect to the
/// tilt: d(Exp(phi) g0)/dphi = -Exp(phi) [g0]x Jr(phi), phi = [theta; 0].
Eigen::Vector3d gravityFromTilt(const double* tilt, const Eigen::Vector3d& g_nominal,
                                Eigen::Matrix<double, 3, kTiltSize>* d_gravity_d_tilt = nullptr);

/// One odometry state in the layout above.
struct StateBlocks {
  std::array<double, kPoseSize> pose{0, 0, 0, 0, 0, 0, 1};
  std::array<double, kMotionSize> motion{};

  static StateBlocks from(const imu::NavState& state, const imu::ImuBias& bias);
  imu::NavState navState() const;
  imu::ImuBias bias() const;
  lie::SE3 T_world_body() const;
};

/// The T_world_body held in a pose block (7 doubles, layout above).
lie::SE3 poseFromBlock(const double* pose_block);
/// Writes T_world_body into a pose block.
void writePoseBlock(const lie::SE3& T_world_body, double* pose_block);
/// The pose block's tangent [dp; dtheta] as an SE(3) right perturbation at T_world_body, to first
/// order: T Exp([R^T dp; dtheta]), i.e. blockdiag(R^T, I). Factors whose residual is written in
/// the SE(3) tangent multiply their Jacobians by it.
lie::Matrix6 poseTangentToSe3(const lie::SE3& T_world_body);

class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseSize; }
  int TangentSize() const override { return kPoseTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace taiga::backend
