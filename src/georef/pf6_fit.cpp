// pf6: the 6-DoF fit on SE(3) with the IMU's absolute orientation (thesis Eq. 45-52). Each fix
// with an orientation at its time gives a measured pose T_enu_meas = (R_enu_body, p_enu of the
// antenna), compared with the trajectory's antenna pose T_world_antenna = T_world_body * (I, lever):
//   r_i = Log(T_enu_meas^-1 * T_enu_world * T_world_antenna)            (6-vector, body tangent)
// Covariance of r_i (thesis Eq. 47), both perturbations transported into the residual's tangent:
//   measurement T_meas Exp(eta): r -> Log(Exp(-eta) E) = Log(E Exp(-Adj(E^-1) eta)),
//   trajectory  T_world_body Exp(eps): r -> Log(E Exp(eps)),            with E = Exp(r),
//   Sigma_r = Jr^-1(r) [Adj(E^-1) Sigma_meas Adj(E^-1)^T + Sigma_traj] Jr^-T(r),
// where Sigma_meas, in the measured body frame, rotates the ENU covariances of the position
// (the fix's) and of the orientation (tilt, heading) by R_enu_body^T: blockdiag(R^T S_p R,
// R^T S_theta R). Gauss-Newton (Eq. 48-52): H delta = -b, H = sum J^T Sigma_r^-1 J, with
// J = d r / d delta (residuals.hpp); covariance sigma0^2 H^-1, sigma0^2 = max(1, chi2 / (6n - 6)).
#include <fmt/format.h>

#include "fit_common.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::georef {

GeorefFit fitPf6(const std::vector<AssociatedFix>& pairs,
                 const std::vector<std::optional<lie::SO3>>& R_enu_body,
                 const FitOptions& options) {
  options.validate();
  if (R_enu_body.size() != pairs.size())
    throw std::invalid_argument("fitPf6: one orientation (or none) per associated fix");
  GeorefFit fit;
  fit.method = GeorefMethod::kPf6;
  fit.inlier.assign(pairs.size(), false);
  std::vector<AssociatedFix> oriented;
  std::vector<lie::SE3> T_enu_meas;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (!R_enu_body[i]) {
      ++fit.without_orientation;
      continue;
    }
    fit.inlier[i] = true;
    oriented.push_back(pairs[i]);
    T_enu_meas.emplace_back(*R_enu_body[i], pairs[i].fix.p_enu);
  }
  if (oriented.size() < 3)
    throw InputError(fmt::format(
        "georef pf6: {} of {} associated fixes have an absolute IMU orientation (ENU or NED) at "
        "their time, at least 3 are needed; the recording's IMU reports none (6-axis IMU, or an "
        "orientation without a known reference). Use --method robust or pf3",
        oriented.size(), pairs.size()));
  detail::requireGeometry(oriented, "pf6", /*needs_3d=*/false);

  const double st = options.orientation_tilt_sigma_rad, sh = options.orientation_heading_sigma_rad;
  const Eigen::Matrix3d sigma_theta_enu = Eigen::Vector3d(st * st, st * st, sh * sh).asDiagonal();
  Matrix6d sigma_traj = Matrix6d::Zero();
  sigma_traj.topLeftCorner<3, 3>().diagonal().setConstant(options.trajectory_position_sigma_m *
                                                          options.trajectory_position_sigma_m);
  sigma_traj.bottomRightCorner<3, 3>().diagonal().setConstant(
      options.trajectory_rotation_sigma_rad * options.trajectory_rotation_sigma_rad);

  const auto linearize = [&](const lie::SE3& T) -> detail::NormalEquations {
    detail::NormalEquations normal;
    for (std::size_t i = 0; i < oriented.size(); ++i) {
      const lie::SE3 T_world_antenna(oriented[i].T_world_body.rotation(), oriented[i].p_world);
      Matrix6d J;
      const Vector6d r = poseResidual(T, T_world_antenna, T_enu_meas[i], &J);
      const Eigen::Matrix3d R_body_enu = T_enu_meas[i].rotation().matrix().transpose();
      Matrix6d sigma_meas = Matrix6d::Zero();
      sigma_meas.topLeftCorner<3, 3>() =
          R_body_enu * oriented[i].fix.covariance_enu_m2 * R_body_enu.transpose();
      sigma_meas.bottomRightCorner<3, 3>() = R_body_enu * sigma_theta_enu * R_body_enu.transpose();
      const Matrix6d adjoint_E_inv = lie::SE3::Exp(r).inverse().adjoint();
      const Matrix6d Jr_inv = lie::SE3::rightJacobianInverse(r);
      const Matrix6d sigma_r =
          Jr_inv * (adjoint_E_inv * sigma_meas * adjoint_E_inv.transpose() + sigma_traj) *
          Jr_inv.transpose();
      const Matrix6d information = sigma_r.ldlt().solve(Matrix6d::Identity());
      normal.H += J.transpose() * information * J;
      normal.b += J.transpose() * information * r;
      normal.chi2 += r.dot(information * r);
    }
    return normal;
  };

  // Start: the closed-form fit when the positions determine a rotation, else the first measured
  // orientation with the centroids' offset (a straight walk on flat ground).
  if (detail::spreadAcrossLine(oriented) >= 0.1) {
    fit.T_enu_world = detail::rigidFit(oriented, std::vector<bool>(oriented.size(), true));
  } else {
    const lie::SO3 R0 = T_enu_meas[0].rotation() * oriented[0].T_world_body.rotation().inverse();
    Eigen::Vector3d offset = Eigen::Vector3d::Zero();
    for (const AssociatedFix& pair : oriented) offset += pair.fix.p_enu - R0 * pair.p_world;
    fit.T_enu_world = lie::SE3(R0, offset / static_cast<double>(oriented.size()));
  }
  detail::gaussNewton(linearize, 6.0 * static_cast<double>(oriented.size()) - 6.0, options, fit);
  detail::finishFit(pairs, options, fit);
  return fit;
}

}  // namespace taiga::georef
