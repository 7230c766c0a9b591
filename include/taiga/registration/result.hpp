#pragma once
// The one result type of every registration method (NDT, D2D-NDT, GICP), after small_gicp's
// RegistrationResult.

#include <cstddef>
#include <limits>
#include <string>

#include "taiga/core/angles.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::registration {

struct RegistrationResult {
  /// Maps source points into the target frame: p_target = T_target_source * p_source.
  lie::SE3 T_target_source;
  /// True when the optimizer stopped on a small step and the problem was not found degenerate.
  bool converged = false;
  int iterations = 0;
  /// Source points (NDT: points or, for D2D, source cells) that found a target cell or a target
  /// correspondence in the last iteration.
  std::size_t num_inliers = 0;
  /// Hessian of the minimized cost at the result, with respect to a right perturbation
  /// T_target_source * Exp(tau), tau = [rho (m); theta (rad)] as in lie/se3.hpp. For GICP this is
  /// the Gauss-Newton Hessian J^T Sigma^-1 J; for NDT the exact Newton Hessian of the score.
  lie::Matrix6 hessian = lie::Matrix6::Zero();
  /// Ratio of the largest to the smallest eigenvalue of `hessian` (infinite when the smallest is
  /// not positive): large values mean a direction the data does not constrain.
  double hessian_condition = std::numeric_limits<double>::infinity();
  /// Condition number of the translation block (rho, rho) of `hessian`: unit-free, about 2-3 for
  /// the real test pair and 77-275 for a corridor (two walls and a floor) whose length leaves a
  /// translation unconstrained. Above the method's max_translation_condition the result is
  /// reported as degenerate (converged = false).
  double translation_condition = std::numeric_limits<double>::infinity();
  /// Final value of the minimized cost (NDT: negative log-likelihood score; GICP: sum of squared
  /// Mahalanobis distances).
  double cost = 0.0;
  /// Thesis fitness score: mean squared distance (m^2) from the registered source points to their
  /// closest target points. NaN when not computed.
  double fitness_m2 = std::numeric_limits<double>::quiet_NaN();
  /// Empty when converged; otherwise why not (empty cloud, too few points, planar input, ...).
  std::string reason;
};

/// How far apart two solutions lie, in metres and degrees of T_a^-1 T_b: what tells distinct
/// solutions from one basin reached twice.
struct Separation {
  double m = 0.0;
  double deg = 0.0;
};
inline Separation separation(const lie::SE3& a, const lie::SE3& b) {
  const lie::Vector6 d = b.minus(a);
  return {d.head<3>().norm(), d.tail<3>().norm() * kDegPerRad};
}

/// Condition number (largest / smallest eigenvalue) of a symmetric 6x6 matrix; infinity when the
/// smallest eigenvalue is not positive.
double conditionNumber(const lie::Matrix6& H);
/// The same for the 3x3 translation block of H.
double translationConditionNumber(const lie::Matrix6& H);

}  // namespace taiga::registration
