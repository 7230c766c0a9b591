// closed: Umeyama/Horn rigid fit of the antenna positions (no scale, unweighted), with the
// covariance of the unweighted least-squares problem: sigma0^2 (sum J_i^T J_i)^-1, where
// sigma0^2 = sum |r_i|^2 / (3n - 6) is the residuals' own variance.
#include "fit_common.hpp"

namespace taiga::georef {

GeorefFit fitClosed(const std::vector<AssociatedFix>& pairs, const FitOptions& options) {
  options.validate();
  detail::requireGeometry(pairs, "closed", /*needs_3d=*/true);
  GeorefFit fit;
  fit.method = GeorefMethod::kClosed;
  fit.inlier.assign(pairs.size(), true);
  fit.T_enu_world = detail::rigidFit(pairs, fit.inlier);
  Matrix6d H = Matrix6d::Zero();
  double sum_squares = 0.0;
  for (const AssociatedFix& pair : pairs) {
    Matrix36d J;
    const Eigen::Vector3d r = positionResidual(fit.T_enu_world, pair.p_world, pair.fix.p_enu, &J);
    H += J.transpose() * J;
    sum_squares += r.squaredNorm();
  }
  const double dof = 3.0 * static_cast<double>(pairs.size()) - 6.0;
  fit.covariance = (sum_squares / dof) * detail::inverseNormal(H);
  fit.iterations = 1;
  detail::finishFit(pairs, options, fit);
  return fit;
}

}  // namespace taiga::georef
