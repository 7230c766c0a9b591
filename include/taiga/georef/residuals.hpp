#pragma once
// The residuals of pf3 and pf6 with their analytic Jacobians, exposed so that tests check them
// against numerical differentiation.
//
// Both perturb T_enu_world on the left in the parameters of fit.hpp: delta = [dt; dtheta],
// T_enu_world' = (Exp(dtheta) R, t + dt).

#include <Eigen/Core>

#include "taiga/lie/se3.hpp"

namespace taiga::georef {

using Matrix36d = Eigen::Matrix<double, 3, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// T_enu_world with the parameter update applied: (Exp(dtheta) R, t + dt).
lie::SE3 applyUpdate(const lie::SE3& T_enu_world, const Vector6d& delta);

/// pf3: r = R p_world + t - p_enu; J = [I, -[R p_world]x].
Eigen::Vector3d positionResidual(const lie::SE3& T_enu_world, const Eigen::Vector3d& p_world,
                                 const Eigen::Vector3d& p_enu, Matrix36d* J = nullptr);

/// pf6: r = Log(T_enu_meas^-1 * T_enu_world * T_world_body), tangent [rho; theta] in the
/// measured body frame. With the parameter update written as a left SE(3) perturbation
/// eps = M delta (M = [I, [t]x; 0, I]) and B = T_enu_world * T_world_body:
/// T_meas^-1 Exp(eps) B = T_meas^-1 B Exp(Adj(B^-1) eps), so J = Jr^-1(r) Adj(B^-1) M.
Vector6d poseResidual(const lie::SE3& T_enu_world, const lie::SE3& T_world_body,
                      const lie::SE3& T_enu_meas, Matrix6d* J = nullptr);

}  // namespace taiga::georef
