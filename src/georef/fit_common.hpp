#pragma once
// Helpers shared by the fitting methods (private to src/georef).

#include <functional>
#include <string_view>
#include <vector>

#include "taiga/georef/fit.hpp"
#include "taiga/georef/residuals.hpp"

namespace taiga::georef::detail {

/// InputError unless there are at least 3 pairs and the antenna positions span more than a line
/// (needs_3d: the second-largest spread) or, for the horizontal-only fit, more than a point
/// horizontally.
void requireGeometry(const std::vector<AssociatedFix>& pairs, std::string_view method,
                     bool needs_3d);

/// Spread of the antenna positions across their main direction (sqrt of the second-largest
/// eigenvalue of their scatter), m: near zero when they lie on a line.
double spreadAcrossLine(const std::vector<AssociatedFix>& pairs);

/// Fills the residual statistics (over the inliers) and inlier counts, inflates the covariance
/// for correlated errors (fit.hpp) and takes the sigmas from it.
void finishFit(const std::vector<AssociatedFix>& pairs, const FitOptions& options, GeorefFit& fit);

/// Unweighted rigid fit of p_world onto p_enu over the pairs with use[i] (Umeyama, no scale).
lie::SE3 rigidFit(const std::vector<AssociatedFix>& pairs, const std::vector<bool>& use);

/// The inverse of a symmetric positive semi-definite normal matrix (LDLT; Eigen's inverse of the
/// decomposition, deterministic).
Matrix6d inverseNormal(const Matrix6d& H);

/// One linearization of a weighted least-squares fit at T_enu_world: H = sum J^T W J,
/// b = sum J^T W r and the weighted squared residual sum chi2 = sum r^T W r.
struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();
  Vector6d b = Vector6d::Zero();
  double chi2 = 0.0;
};

/// Gauss-Newton for pf3 and pf6 from fit.T_enu_world: steps H delta = -b applied with
/// applyUpdate (residuals.hpp) until the step is below options.convergence_step or
/// options.max_iterations; sets T_enu_world, iterations, converged and the covariance
/// sigma0^2 H^-1 with sigma0^2 = max(1, chi2 / dof) at the solution.
void gaussNewton(const std::function<NormalEquations(const lie::SE3&)>& linearize, double dof,
                 const FitOptions& options, GeorefFit& fit);

}  // namespace taiga::georef::detail
