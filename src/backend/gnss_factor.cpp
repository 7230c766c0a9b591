#include "taiga/backend/gnss_factor.hpp"

#include <Eigen/Cholesky>
#include <cmath>

#include "taiga/backend/sqrt_information.hpp"

namespace taiga::backend {
namespace {

Eigen::Matrix3d yawRotation(double yaw_rad) {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  Eigen::Matrix3d Rz;
  Rz << c, -s, 0, s, c, 0, 0, 0, 1;
  return Rz;
}

}  // namespace

lie::SE3 enuWorldFromBlock(const double* enu_block) {
  return {lie::SO3::fromMatrix(yawRotation(enu_block[3])),
          Eigen::Vector3d(enu_block[0], enu_block[1], enu_block[2])};
}

void writeEnuWorldBlock(const lie::SE3& T_enu_world, double* enu_block) {
  enu_block[0] = T_enu_world.translation().x();
  enu_block[1] = T_enu_world.translation().y();
  enu_block[2] = T_enu_world.translation().z();
  enu_block[3] = T_enu_world.rotation().yaw();  // heading of the world's x axis in ENU
}

GnssFactor::GnssFactor(const Eigen::Vector3d& d_body, const Eigen::Vector3d& p_enu,
                       const Eigen::Matrix3d& covariance_enu_m2)
    : d_body_(d_body), p_enu_(p_enu), sqrt_information_(sqrtInformation<3>(covariance_enu_m2)) {}

bool GnssFactor::Evaluate(double const* const* parameters, double* residuals,
                          double** jacobians) const {
  const lie::SE3 T_world_body = poseFromBlock(parameters[0]);
  const double* enu = parameters[1];
  const Eigen::Matrix3d Rz = yawRotation(enu[3]);
  const Eigen::Vector3d p_world = T_world_body * d_body_;
  const Eigen::Vector3d p_enu_predicted = Rz * p_world + Eigen::Vector3d(enu[0], enu[1], enu[2]);
  Eigen::Map<Eigen::Vector3d>{residuals} = sqrt_information_ * (p_enu_predicted - p_enu_);
  if (!jacobians) return true;
  if (jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 3, kPoseSize, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.leftCols<3>() = sqrt_information_ * Rz;
    J.middleCols<3>(3) =
        -sqrt_information_ * Rz * T_world_body.rotation().matrix() * lie::hat(d_body_);
  }
  if (jacobians[1]) {
    Eigen::Map<Eigen::Matrix<double, 3, kEnuWorldSize, Eigen::RowMajor>> J(jacobians[1]);
    J.leftCols<3>() = sqrt_information_;
    J.col(3) = sqrt_information_ * Eigen::Vector3d::UnitZ().cross(Rz * p_world);
  }
  return true;
}

}  // namespace taiga::backend
