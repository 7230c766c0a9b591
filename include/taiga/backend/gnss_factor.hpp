#pragma once
// A GNSS fix in the mapping graph (thesis Eq. 43), with the map-to-ENU transform as an unknown.
//
// The map (world) frame is gravity-aligned but its heading and origin are wherever the odometry
// started, so a fix in local ENU cannot be compared with a world position directly. The graph
// therefore estimates T_enu_world with 4 DoF, yaw and translation; roll and pitch are zero
// because both frames have z up (to the deflection of the vertical, arc seconds). The factor
// attaches the fix to one keyframe k:
//
//   p_world = T_world_k * d_k                        (d_k: the antenna at the fix's time in k's
//                                                     body frame, from the odometry; constant)
//   r       = L^T (Rz(yaw) p_world + t - p_enu)      (L L^T = Sigma_enu^-1, the fix's covariance)
//
// Parameter blocks: the keyframe's pose block (7, state_blocks.hpp; tangent [dp world; dtheta
// body]) and the ENU block (4): [t_east, t_north, t_up (m); yaw (rad)], no manifold needed.
// Jacobians (checked numerically in tests/backend/factor_jacobians_test.cpp):
//   dr/ddp     = L^T Rz
//   dr/ddtheta = -L^T Rz R_world_k [d_k]x          (R Exp(dtheta) d ~ R d + R [dtheta]x d)
//   dr/dt      = L^T
//   dr/dyaw    = L^T [e_z]x Rz p_world

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "taiga/backend/state_blocks.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::backend {

constexpr int kEnuWorldSize = 4;

/// T_enu_world from an ENU block [t_east, t_north, t_up, yaw_rad].
lie::SE3 enuWorldFromBlock(const double* enu_block);
/// Writes the yaw and translation of T_enu_world into an ENU block; roll and pitch are dropped
/// (the caller's transform should have none).
void writeEnuWorldBlock(const lie::SE3& T_enu_world, double* enu_block);

class GnssFactor final : public ceres::SizedCostFunction<3, kPoseSize, kEnuWorldSize> {
 public:
  /// `d_body`: the antenna in the keyframe's body frame at the fix time (m); `p_enu` and
  /// `covariance_enu_m2`: the fix in local ENU.
  GnssFactor(const Eigen::Vector3d& d_body, const Eigen::Vector3d& p_enu,
             const Eigen::Matrix3d& covariance_enu_m2);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d d_body_;
  Eigen::Vector3d p_enu_;
  Eigen::Matrix3d sqrt_information_;
};

}  // namespace taiga::backend
