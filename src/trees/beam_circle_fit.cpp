#include "taiga/trees/beam_circle_fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "circle_coverage.hpp"

namespace taiga::trees {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using Matrix23d = Eigen::Matrix<double, 2, 3>;

constexpr double kTukey = 3.0;  // the biweight's cut on the Mahalanobis norm

// A point's whitened residual (along its beam, across it) and its rows of the Jacobian in
// (cx, cy, r).
struct Whitened {
  Vector2d e;
  Matrix23d J;
};

// The residual to the circle point q(psi) = c + r (cos psi v + sin psi u) nearest in the
// Mahalanobis sense, psi in [pi/2, 3 pi/2] (the half whose normal faces the sensor). With
// a = (p - c).v and b = (p - c).u the cost is f = (a - r cos psi)^2 / s_v^2 + (b - r sin psi)^2 /
// s_u^2, minimised by safeguarded Newton steps from the beam's near-side intersection
// (psi = pi - asin(b / r); at the silhouette when the beam misses). By the envelope theorem the
// Jacobian is taken at that psi: d(p - q)/dc = -I, d(p - q)/dr = -(cos psi v + sin psi u).
Whitened beamResidual(const Vector2d& p, const Vector2d& v, const Circle& circle, double sigma_v_m,
                      double sigma_u_m) {
  const double r = circle.radius_m;
  const Vector2d d = p - circle.center_m;
  if (!(v.squaredNorm() > 0.5)) {  // no beam: across the surface, in units of the range sigma
    const double distance = std::max(d.norm(), 1e-9);
    Whitened w{Vector2d((distance - r) / sigma_v_m, 0.0), Matrix23d::Zero()};
    w.J.row(0) << -d.x() / distance / sigma_v_m, -d.y() / distance / sigma_v_m, -1.0 / sigma_v_m;
    return w;
  }
  const Vector2d u(-v.y(), v.x());
  const double a = d.dot(v), b = d.dot(u);
  const double iv = 1.0 / (sigma_v_m * sigma_v_m), iu = 1.0 / (sigma_u_m * sigma_u_m);
  auto cost = [&](double psi) {
    const double ea = a - r * std::cos(psi), eb = b - r * std::sin(psi);
    return ea * ea * iv + eb * eb * iu;
  };
  constexpr double kLo = 0.5 * std::numbers::pi, kHi = 1.5 * std::numbers::pi;
  double psi = std::numbers::pi - std::asin(std::clamp(b / r, -1.0, 1.0));
  double f = cost(psi);
  for (int k = 0; k < 6; ++k) {
    const double s = std::sin(psi), c = std::cos(psi);
    const double ea = a - r * c, eb = b - r * s;
    const double g = r * (ea * s * iv - eb * c * iu);                              // f' / 2
    const double h = r * ((r * s * s + ea * c) * iv + (r * c * c + eb * s) * iu);  // f'' / 2
    double step = -g / std::max(h, 0.1 * r * r * std::max(iv, iu));
    bool moved = false;
    for (int halving = 0; halving < 4 && !moved; ++halving, step *= 0.5) {
      const double next = std::clamp(psi + step, kLo, kHi);
      const double f_next = cost(next);
      if (f_next < f) psi = next, f = f_next, moved = true;
    }
    if (!moved || std::abs(step) < 1e-6) break;
  }
  const Vector2d n = std::cos(psi) * v + std::sin(psi) * u;
  const Vector2d e = d - r * n;
  Whitened w{Vector2d(e.dot(v) / sigma_v_m, e.dot(u) / sigma_u_m), Matrix23d::Zero()};
  w.J.row(0) << -v.x() / sigma_v_m, -v.y() / sigma_v_m, -n.dot(v) / sigma_v_m;
  w.J.row(1) << -u.x() / sigma_u_m, -u.y() / sigma_u_m, -n.dot(u) / sigma_u_m;
  return w;
}

struct Irls {
  double cost = std::numeric_limits<double>::infinity();  // sum of Tukey's rho
  Eigen::Matrix3d JtWJ = Eigen::Matrix3d::Zero();
  double weighted_sq = 0.0, weight_sum = 0.0;
  std::vector<double> weights;
};

// Iteratively reweighted Gauss-Newton from `circle` (moved in place), on the centre alone or on
// centre and radius; the state at the last circle.
Irls irls(std::span<const Vector2d> points_m, std::span<const Vector2d> beams, Circle& circle,
          double sigma_v_m, double sigma_u_m, bool fit_radius, int iterations) {
  Irls state;
  state.weights.assign(points_m.size(), 0.0);
  for (int iteration = 0; iteration <= iterations; ++iteration) {
    state.cost = state.weighted_sq = state.weight_sum = 0.0;
    state.JtWJ.setZero();
    Vector3d JtWe = Vector3d::Zero();
    for (std::size_t i = 0; i < points_m.size(); ++i) {
      const Whitened r = beamResidual(points_m[i], beams[i], circle, sigma_v_m, sigma_u_m);
      const double u2 = r.e.squaredNorm() / (kTukey * kTukey);
      const double w = u2 < 1.0 ? (1.0 - u2) * (1.0 - u2) : 0.0;
      state.weights[i] = w;
      state.cost +=
          kTukey * kTukey / 6.0 * (u2 < 1.0 ? 1.0 - (1.0 - u2) * (1.0 - u2) * (1.0 - u2) : 1.0);
      if (w == 0.0) continue;
      // Gauss-Newton on the scalar m = |e| (psi eliminated): its gradient is J^T e / |e|. The
      // rows' J^T J instead would ignore that q slides along the circle, and on a stiff ratio
      // sigma_v / sigma_u the steps would crawl.
      const Vector3d Jte = r.J.transpose() * r.e;
      const double e2 = r.e.squaredNorm();
      state.JtWJ += e2 > 1e-18 ? Eigen::Matrix3d(w * Jte * Jte.transpose() / e2)
                               : Eigen::Matrix3d(w * r.J.transpose() * r.J);
      JtWe += w * Jte;
      state.weighted_sq += w * e2;
      state.weight_sum += w;
    }
    if (iteration == iterations) break;
    Vector3d step = Vector3d::Zero();
    if (fit_radius) {
      step = state.JtWJ.ldlt().solve(-JtWe);
    } else {
      step.head<2>() = state.JtWJ.topLeftCorner<2, 2>().ldlt().solve(-JtWe.head<2>());
    }
    if (!step.allFinite()) break;
    circle.center_m += step.head<2>();
    circle.radius_m += step.z();
    if (step.norm() < 1e-7) iterations = iteration + 1;  // one more pass for the final state
  }
  return state;
}

// The start for the joint fit: the circle of lowest robust cost over radii 0.6-2 times the
// start's, each with its centre fitted (5 passes), on at most 128 points (every k-th).
Circle profiledStart(std::span<const Vector2d> points_m, std::span<const Vector2d> beams,
                     const Circle& start, double sigma_v_m, double sigma_u_m,
                     const CircleFitOptions& options) {
  // The sensors' side: a one-sided arc's centre lies behind its surface, so a larger radius moves
  // it away from the sensors (by the mean beam; near zero for a stem seen all around).
  Vector2d mean_beam = Vector2d::Zero();
  for (const Vector2d& v : beams) mean_beam += v;
  mean_beam /= static_cast<double>(beams.size());
  const std::size_t stride = (points_m.size() + 127) / 128;
  std::vector<Vector2d> sample_points, sample_beams;
  for (std::size_t i = 0; i < points_m.size(); i += stride) {
    sample_points.push_back(points_m[i]);
    sample_beams.push_back(beams[i]);
  }
  Circle best = start;
  double best_cost = std::numeric_limits<double>::infinity();
  for (double factor = 0.6; factor < 2.05; factor *= 1.15) {
    const double r = factor * start.radius_m;
    if (r < options.min_radius_m || r > options.max_radius_m) continue;
    Circle circle{start.center_m + (r - start.radius_m) * mean_beam, r};
    const Irls profile = irls(sample_points, sample_beams, circle, sigma_v_m, sigma_u_m, false, 5);
    if (profile.cost < best_cost) best_cost = profile.cost, best = circle;
  }
  return best;
}

}  // namespace

std::optional<CircleFit> fitCircleAlongBeams(std::span<const Vector2d> points_m,
                                             std::span<const Vector2d> beams,
                                             const Vector2d& start_center_m, double start_radius_m,
                                             double range_sigma_m,
                                             const CircleFitOptions& options) {
  if (points_m.size() < 5 || beams.size() != points_m.size() || !(start_radius_m > 0.0))
    return std::nullopt;
  const double sigma_v_m = range_sigma_m, sigma_u_m = options.across_beam_sigma_m;
  Circle circle = profiledStart(points_m, beams, {start_center_m, start_radius_m}, sigma_v_m,
                                sigma_u_m, options);
  const Irls state = irls(points_m, beams, circle, sigma_v_m, sigma_u_m, true, 30);
  const auto kept =
      std::count_if(state.weights.begin(), state.weights.end(), [](double w) { return w > 0.0; });
  if (kept < 5 ||
      !(circle.radius_m >= options.min_radius_m && circle.radius_m <= options.max_radius_m))
    return std::nullopt;

  CircleFit fit;
  fit.center_m = circle.center_m;
  fit.radius_m = circle.radius_m;
  double inlier_sq = 0.0;
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    if (state.weights[i] <= 0.0) continue;
    // The RMS measures the surface's scatter across it, as refineCircle's.
    const double across_m = (points_m[i] - circle.center_m).norm() - circle.radius_m;
    inlier_sq += across_m * across_m;
    ++fit.inliers;
    fit.along_beams = fit.along_beams || beams[i].squaredNorm() > 0.5;
  }
  fit.rms_m = std::sqrt(inlier_sq / static_cast<double>(fit.inliers));
  // Covariance of (cx, cy, r): s^2 (J^T W J)^-1, s^2 the weighted variance of m = |e| (near 1
  // when the sigmas are honest).
  const double dof = std::max(1.0, state.weight_sum - 3.0);
  describeFit(fit, points_m, state.weights, (state.weighted_sq / dof) * state.JtWJ.inverse());
  return fit;
}

}  // namespace taiga::trees
