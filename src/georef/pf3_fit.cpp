// pf3: the thesis' ICP-like fit of positions with time-interpolated correspondences (the
// association), Gauss-Newton on the 6 parameters of T_enu_world. Each residual
// r_i = R p_world,i + t - p_enu,i is weighted by the inverse of the combined covariance
// (thesis Eq. 44)
//   Sigma_i = Sigma_gnss,i + R Sigma_traj R^T,
// recomputed with the current R every iteration. Normal equations H delta = -b with
// H = sum J_i^T Sigma_i^-1 J_i, b = sum J_i^T Sigma_i^-1 r_i (J_i in residuals.hpp). Covariance:
// sigma0^2 H^-1 with the variance factor sigma0^2 = max(1, sum r_i^T Sigma_i^-1 r_i / (3n - 6)).
#include "fit_common.hpp"

namespace taiga::georef {

GeorefFit fitPf3(const std::vector<AssociatedFix>& pairs, const FitOptions& options) {
  options.validate();
  detail::requireGeometry(pairs, "pf3", /*needs_3d=*/true);
  GeorefFit fit;
  fit.method = GeorefMethod::kPf3;
  fit.inlier.assign(pairs.size(), true);
  fit.T_enu_world = detail::rigidFit(pairs, fit.inlier);
  const Eigen::Matrix3d sigma_traj_world =
      options.trajectory_position_sigma_m * options.trajectory_position_sigma_m *
      Eigen::Matrix3d::Identity();

  const auto linearize = [&](const lie::SE3& T) -> detail::NormalEquations {
    detail::NormalEquations normal;
    const Eigen::Matrix3d R = T.rotation().matrix();
    for (const AssociatedFix& pair : pairs) {
      Matrix36d J;
      const Eigen::Vector3d r = positionResidual(T, pair.p_world, pair.fix.p_enu, &J);
      const Eigen::Matrix3d information =
          (pair.fix.covariance_enu_m2 + R * sigma_traj_world * R.transpose()).inverse();
      normal.H += J.transpose() * information * J;
      normal.b += J.transpose() * information * r;
      normal.chi2 += r.dot(information * r);
    }
    return normal;
  };

  detail::gaussNewton(linearize, 3.0 * static_cast<double>(pairs.size()) - 6.0, options, fit);
  detail::finishFit(pairs, options, fit);
  return fit;
}

}  // namespace taiga::georef
