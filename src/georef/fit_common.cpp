#include "fit_common.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "taiga/core/errors.hpp"
#include "taiga/lie/umeyama.hpp"

namespace taiga::georef::detail {

namespace {
Eigen::Matrix3d scatterOf(const std::vector<AssociatedFix>& pairs) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const AssociatedFix& pair : pairs) mean += pair.p_world;
  mean /= static_cast<double>(pairs.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const AssociatedFix& pair : pairs)
    scatter += (pair.p_world - mean) * (pair.p_world - mean).transpose();
  return scatter / static_cast<double>(pairs.size());
}
}  // namespace

double spreadAcrossLine(const std::vector<AssociatedFix>& pairs) {
  if (pairs.empty()) return 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatterOf(pairs),
                                                              Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, solver.eigenvalues()[1]));
}

void requireGeometry(const std::vector<AssociatedFix>& pairs, std::string_view method,
                     bool needs_3d) {
  if (pairs.size() < 3)
    throw InputError(fmt::format(
        "georef {}: {} fix(es) associated with the trajectory, at least 3 are needed", method,
        pairs.size()));
  constexpr double kMinSpread_m = 0.1;
  if (needs_3d) {
    const double spread_m = spreadAcrossLine(pairs);
    if (spread_m < kMinSpread_m)
      throw InputError(fmt::format(
          "georef {}: the trajectory's positions at the {} fixes lie on a line (spread across it "
          "{:.3f} m < {} m), so the rotation about that line is not determined; use --method robust",
          method, pairs.size(), spread_m, kMinSpread_m));
  } else if (scatterOf(pairs).topLeftCorner<2, 2>().trace() < 1.0) {
    throw InputError(fmt::format(
        "georef {}: the trajectory moves less than 1 m horizontally over the {} fixes, so its "
        "heading is not determined",
        method, pairs.size()));
  }
}

void finishFit(const std::vector<AssociatedFix>& pairs, const FitOptions& options, GeorefFit& fit) {
  double sum3 = 0.0, sum_h = 0.0, sum_v = 0.0;
  fit.inliers = 0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (!fit.inlier[i]) continue;
    const Eigen::Vector3d r = fit.T_enu_world * pairs[i].p_world - pairs[i].fix.p_enu;
    sum3 += r.squaredNorm();
    sum_h += r.head<2>().squaredNorm();
    sum_v += r.z() * r.z();
    ++fit.inliers;
  }
  const double n = static_cast<double>(std::max<std::size_t>(fit.inliers, 1));
  fit.residual_rms_m = std::sqrt(sum3 / n);
  fit.horizontal_rms_m = std::sqrt(sum_h / n);
  fit.vertical_rms_m = std::sqrt(sum_v / n);
  // Variance of the mean of m Gauss-Markov samples relative to white noise (fit.hpp); a fit
  // that models the correlation (robust) needs none.
  fit.correlation_inflation = 1.0;
  if (!fit.error_model && options.error_correlation_time_s > 0.0 && fit.inliers > 0) {
    double sum = 0.0;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      if (!fit.inlier[i]) continue;
      for (std::size_t j = 0; j < pairs.size(); ++j) {
        if (!fit.inlier[j]) continue;
        sum += std::exp(-std::abs(pairs[i].fix.t_s - pairs[j].fix.t_s) /
                        options.error_correlation_time_s);
      }
    }
    fit.correlation_inflation = sum / static_cast<double>(fit.inliers);
  }
  fit.covariance = fit.correlation_inflation * 0.5 * (fit.covariance + fit.covariance.transpose());
  fit.sigma = fit.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
}

lie::SE3 rigidFit(const std::vector<AssociatedFix>& pairs, const std::vector<bool>& use) {
  std::vector<Eigen::Vector3d> p_world, p_enu;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (!use[i]) continue;
    p_world.push_back(pairs[i].p_world);
    p_enu.push_back(pairs[i].fix.p_enu);
  }
  // The callers have checked that the trajectory's positions span more than a line; the fixes'
  // positions may still not (all at one spot).
  const int rank = lie::crossCovarianceRank(p_world, p_enu);
  if (rank < 2)
    throw InputError(fmt::format(
        "georef: the positions of the {} fixes do not determine a rotation (their covariance with "
        "the trajectory's has rank {} < 2)",
        p_world.size(), rank));
  return lie::umeyama(p_world, p_enu, /*with_scale=*/false).T_target_source;
}

Matrix6d inverseNormal(const Matrix6d& H) {
  return H.ldlt().solve(Matrix6d::Identity());
}

void gaussNewton(const std::function<NormalEquations(const lie::SE3&)>& linearize, double dof,
                 const FitOptions& options, GeorefFit& fit) {
  fit.converged = false;
  NormalEquations normal = linearize(fit.T_enu_world);
  for (fit.iterations = 1; fit.iterations <= options.max_iterations; ++fit.iterations) {
    const Vector6d delta = -normal.H.ldlt().solve(normal.b);
    fit.T_enu_world = applyUpdate(fit.T_enu_world, delta);
    normal = linearize(fit.T_enu_world);
    if (delta.norm() < options.convergence_step) {
      fit.converged = true;
      break;
    }
  }
  fit.iterations = std::min(fit.iterations, options.max_iterations);
  fit.covariance = std::max(1.0, normal.chi2 / dof) * inverseNormal(normal.H);
}

}  // namespace taiga::georef::detail
