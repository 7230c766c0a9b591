#include "taiga/georef/residuals.hpp"

namespace taiga::georef {

lie::SE3 applyUpdate(const lie::SE3& T_enu_world, const Vector6d& delta) {
  return {lie::SO3::Exp(delta.tail<3>()) * T_enu_world.rotation(),
          T_enu_world.translation() + delta.head<3>()};
}

Eigen::Vector3d positionResidual(const lie::SE3& T_enu_world, const Eigen::Vector3d& p_world,
                                 const Eigen::Vector3d& p_enu, Matrix36d* J) {
  const Eigen::Vector3d Rp = T_enu_world.rotation() * p_world;
  if (J) {
    // d(Exp(dtheta) R p)/d(dtheta) = -[R p]x at dtheta = 0.
    J->leftCols<3>().setIdentity();
    J->rightCols<3>() = -lie::hat(Rp);
  }
  return Rp + T_enu_world.translation() - p_enu;
}

Vector6d poseResidual(const lie::SE3& T_enu_world, const lie::SE3& T_world_body,
                      const lie::SE3& T_enu_meas, Matrix6d* J) {
  const lie::SE3 B = T_enu_world * T_world_body;
  const Vector6d r = (T_enu_meas.inverse() * B).Log();
  if (J) {
    // Left SE(3) perturbation of T_enu_world equivalent to the parameter update, to first order:
    // Exp(eps) T has translation t + rho + theta x t, so rho = dt + [t]x dtheta.
    Matrix6d M = Matrix6d::Identity();
    M.topRightCorner<3, 3>() = lie::hat(T_enu_world.translation());
    *J = lie::SE3::rightJacobianInverse(r) * B.inverse().adjoint() * M;
  }
  return r;
}

}  // namespace taiga::georef
