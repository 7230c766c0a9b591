// robust: each degree of freedom from the data that carries it (the thesis' recommendation).
//
// Roll and pitch: zero. The map is gravity-aligned (z up) and so is ENU to within the deflection
// of the vertical (arc seconds); GNSS heights, worse than the horizontal positions by about 2x
// under canopy, would only add noise. Their sigma is FitOptions::gravity_tilt_sigma_rad.
//
// Yaw and horizontal offset: a 2D rigid fit of the horizontal track, a_i = (x, y) of p_world,i
// onto b_i = (e, n) of p_enu,i, minimizing sum w_i |R(psi) a_i + t - b_i|^2 / s_i^2 (s_i^2 the
// mean of the fix's east and north variances) in closed form (weighted 2D Procrustes:
// psi = atan2(sum w s^-2 (a' x b'), sum w s^-2 (a' . b')) on the weighted-centred points,
// t = b_mean - R a_mean), iterated with Cauchy weights (IRLS)
//   w_i = 1 / (1 + (u_i / (c k))^2),  u_i = |r_i| / s_i,  k = median(u) / 1.1774,
// k being the robust scale of the normalized residual norms (1.1774 is the median of the norm of
// a 2D unit Gaussian), which absorbs a receiver's optimistic sigmas. Fixes with
// u_i / k > outlier_threshold (multipath jumps) are then outliers; a weighted fit of the
// inliers starts the final estimate.
//
// Height offset: first a Huber M-estimate of the height differences d_i = u_i - z_world,i
// (weights min(1, h / |v_i|), v_i = (d_i - t_u) / (sigma_up,i k_u), k_u = 1.4826 MAD), from the
// median, only to screen outliers.
//
// The estimate and its uncertainty: generalized least squares of (t_e, t_n, psi) and t_u over
// the inliers under the Gauss-Markov error model of the fixes (gauss_markov.hpp), which also
// screens the multipath that plain residuals hide. Its covariance is the model's expected error
// for these fixes, scaled by the whitened residuals; no further inflation for correlation.
#include <algorithm>
#include <cmath>

#include "fit_common.hpp"

namespace taiga::georef {
namespace {

constexpr double kRayleighMedian = 1.1774100225154747;  // sqrt(2 ln 2)
constexpr double kMadToSigma = 1.482602218505602;

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  const double upper = *middle;
  const double lower = *std::max_element(values.begin(), middle);
  return 0.5 * (lower + upper);
}

struct Horizontal {
  double yaw_rad = 0.0;
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
};

/// Weighted 2D Procrustes: the yaw and offset minimizing sum weight_i |R a_i + t - b_i|^2.
Horizontal fit2d(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                 const std::vector<double>& weight) {
  double total = 0.0;
  Eigen::Vector2d mean_a = Eigen::Vector2d::Zero(), mean_b = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) {
    total += weight[i];
    mean_a += weight[i] * a[i];
    mean_b += weight[i] * b[i];
  }
  mean_a /= total;
  mean_b /= total;
  double cross = 0.0, dot = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector2d ca = a[i] - mean_a, cb = b[i] - mean_b;
    cross += weight[i] * (ca.x() * cb.y() - ca.y() * cb.x());
    dot += weight[i] * ca.dot(cb);
  }
  Horizontal h;
  h.yaw_rad = std::atan2(cross, dot);
  h.t = mean_b - Eigen::Rotation2Dd(h.yaw_rad) * mean_a;
  return h;
}

}  // namespace

GeorefFit fitRobust(const std::vector<AssociatedFix>& pairs, const FitOptions& options) {
  options.validate();
  detail::requireGeometry(pairs, "robust", /*needs_3d=*/false);
  const std::size_t n = pairs.size();
  std::vector<Eigen::Vector2d> a(n), b(n);
  std::vector<double> s2(n), height_difference(n), sigma_up(n);
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = pairs[i].p_world.head<2>();
    b[i] = pairs[i].fix.p_enu.head<2>();
    const Eigen::Matrix3d& covariance = pairs[i].fix.covariance_enu_m2;
    s2[i] = 0.5 * (covariance(0, 0) + covariance(1, 1));
    height_difference[i] = pairs[i].fix.p_enu.z() - pairs[i].p_world.z();
    sigma_up[i] = std::sqrt(covariance(2, 2));
  }

  GeorefFit fit;
  fit.method = GeorefMethod::kRobust;
  fit.converged = false;

  // Horizontal: Cauchy IRLS from the Gaussian (weights 1/s^2) fit.
  std::vector<double> cauchy(n, 1.0), weight(n), u(n);
  const auto weights = [&](const std::vector<bool>* use) {
    for (std::size_t i = 0; i < n; ++i)
      weight[i] = (use && !(*use)[i]) ? 0.0 : cauchy[i] / s2[i];
  };
  const auto normalizedResiduals = [&](const Horizontal& h) {
    for (std::size_t i = 0; i < n; ++i)
      u[i] = (Eigen::Rotation2Dd(h.yaw_rad) * a[i] + h.t - b[i]).norm() / std::sqrt(s2[i]);
  };
  weights(nullptr);
  Horizontal horizontal = fit2d(a, b, weight);
  double scale = 1.0;
  for (fit.iterations = 1; fit.iterations <= options.max_iterations; ++fit.iterations) {
    normalizedResiduals(horizontal);
    scale = std::max(median(u) / kRayleighMedian, 1e-9);
    for (std::size_t i = 0; i < n; ++i) {
      const double x = u[i] / (options.cauchy_scale * scale);
      cauchy[i] = 1.0 / (1.0 + x * x);
    }
    weights(nullptr);
    const Horizontal next = fit2d(a, b, weight);
    const double step = std::abs(next.yaw_rad - horizontal.yaw_rad) + (next.t - horizontal.t).norm();
    horizontal = next;
    if (step < options.convergence_step) {
      fit.converged = true;
      break;
    }
  }
  fit.iterations = std::min(fit.iterations, options.max_iterations);

  // Height: Huber M-estimate of the offset, from the median.
  double t_up = median(height_difference);
  const auto heightScale = [&](double offset) {
    std::vector<double> deviation(n);
    for (std::size_t i = 0; i < n; ++i)
      deviation[i] = std::abs(height_difference[i] - offset) / sigma_up[i];
    return std::max(kMadToSigma * median(deviation), 1e-9);
  };
  double scale_up = heightScale(t_up);
  std::vector<double> huber(n, 1.0);
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    double numerator = 0.0, denominator = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double v = std::abs(height_difference[i] - t_up) / (sigma_up[i] * scale_up);
      huber[i] = v <= options.huber_threshold ? 1.0 : options.huber_threshold / v;
      numerator += huber[i] * height_difference[i] / (sigma_up[i] * sigma_up[i]);
      denominator += huber[i] / (sigma_up[i] * sigma_up[i]);
    }
    const double next = numerator / denominator;
    const double step = std::abs(next - t_up);
    t_up = next;
    if (step < options.convergence_step) break;
  }
  scale_up = heightScale(t_up);

  // Outliers: a multipath jump moves a fix in all directions, so a fix far off horizontally or
  // vertically is dropped from both fits.
  normalizedResiduals(horizontal);
  fit.inlier.assign(n, true);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = std::abs(height_difference[i] - t_up) / (sigma_up[i] * scale_up);
    fit.inlier[i] = u[i] / scale <= options.outlier_threshold && v <= options.outlier_threshold;
  }
  const std::size_t inliers =
      static_cast<std::size_t>(std::count(fit.inlier.begin(), fit.inlier.end(), true));
  if (inliers >= 3) {
    weights(&fit.inlier);
    horizontal = fit2d(a, b, weight);
  } else {
    fit.inlier.assign(n, true);  // too few left to reject anything
  }

  // Final estimate: generalized least squares on the inliers under the Gauss-Markov error model.
  const GaussMarkovFit gls = fitGaussMarkov(pairs, fit.inlier, horizontal.yaw_rad, horizontal.t,
                                            {.correlation_time_s = options.error_correlation_time_s,
                                             .outlier_sigmas = options.outlier_threshold,
                                             .model = options.error_model});
  fit.inlier = gls.used;
  fit.outliers =
      n - static_cast<std::size_t>(std::count(fit.inlier.begin(), fit.inlier.end(), true));
  fit.T_enu_world = lie::SE3(lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), gls.yaw_rad),
                             Eigen::Vector3d(gls.t.x(), gls.t.y(), gls.t_up));
  const int index[3] = {0, 1, 5};  // east, north, yaw in the 6-DoF parameter order
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      fit.covariance(index[r], index[c]) = gls.horizontal_covariance(r, c);
  fit.covariance(2, 2) = gls.up_variance;
  fit.covariance(3, 3) = fit.covariance(4, 4) =
      options.gravity_tilt_sigma_rad * options.gravity_tilt_sigma_rad;
  fit.error_model = gls.model;
  detail::finishFit(pairs, options, fit);
  return fit;
}

}  // namespace taiga::georef
