// Newton optimization of the NDT score (P2D and D2D), optionally coarse to fine.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "taiga/registration/degeneracy.hpp"
#include "taiga/registration/ndt.hpp"

namespace taiga::registration {
namespace {

constexpr std::size_t kMinSourcePoints = 10;
constexpr int kMaxLineSearchSteps = 10;
constexpr double kRotationLever_m = 5.0;

using Evaluate = std::function<NdtDerivatives(const lie::SE3&, bool)>;

// Newton step -H^-1 g with H made positive definite by taking absolute eigenvalues (floored at
// 1e-9 of the largest), so that the step descends even where the score is not convex.
lie::Vector6 newtonStep(const lie::Matrix6& H, const lie::Vector6& g) {
  Eigen::SelfAdjointEigenSolver<lie::Matrix6> solver(H);
  lie::Vector6 lambda = solver.eigenvalues().cwiseAbs();
  const double floor = std::max(lambda.maxCoeff() * 1e-9, 1e-12);
  lambda = lambda.cwiseMax(floor);
  const lie::Matrix6& V = solver.eigenvectors();
  return -(V * lambda.cwiseInverse().asDiagonal() * V.transpose()) * g;
}

RegistrationResult newton(const Evaluate& evaluate, const lie::SE3& guess, const NdtConfig& config,
                          double max_step_m) {
  RegistrationResult result;
  lie::SE3 T = guess;
  NdtDerivatives D = evaluate(T, true);
  bool small_step = false;
  for (int it = 1; it <= config.max_iterations && !small_step; ++it) {
    if (D.num_inliers == 0) break;
    lie::Vector6 step = newtonStep(D.hessian, D.gradient);
    // The step is shortened (direction kept) to at most max_step_m of translation and to a
    // rotation that moves a point kRotationLever_m away by no more than that. Far from the
    // optimum the modified Newton step of this non-convex score can turn by tens of degrees; the
    // line search would then halve it several times, each halving a pass over the scan.
    const double shrink = std::max({1.0, step.head<3>().norm() / max_step_m,
                                    step.tail<3>().norm() * kRotationLever_m / max_step_m});
    step /= shrink;
    result.iterations = it;
    if (step.head<3>().norm() < config.step_epsilon_m &&
        step.tail<3>().norm() < config.step_epsilon_rad) {
      small_step = true;  // the full Newton step is below the tolerance: done, without taking it
      break;
    }
    // Backtracking (Armijo) line search. The full step is evaluated with derivatives, since it
    // is usually accepted; shorter ones with the score only, then derivatives where accepted.
    const double slope = D.gradient.dot(step);  // < 0 for a descent direction
    double alpha = 1.0;
    bool accepted = false;
    for (int ls = 0; ls < kMaxLineSearchSteps; ++ls, alpha *= 0.5) {
      const lie::SE3 candidate = T.plus(alpha * step);
      NdtDerivatives Dc = evaluate(candidate, ls == 0);
      if (Dc.score <= D.score + 1e-4 * alpha * slope) {
        T = candidate;
        D = ls == 0 ? std::move(Dc) : evaluate(T, true);
        accepted = true;
        break;
      }
    }
    const lie::Vector6 taken = accepted ? lie::Vector6(alpha * step) : lie::Vector6::Zero();
    // No decrease along a descent direction within 2^-10 of the step: at the minimum to within
    // the resolution of the line search.
    small_step = !accepted || (taken.head<3>().norm() < config.step_epsilon_m &&
                               taken.tail<3>().norm() < config.step_epsilon_rad);
  }
  result.T_target_source = T;
  result.num_inliers = D.num_inliers;
  result.hessian = D.hessian;
  result.hessian_condition = conditionNumber(D.hessian);
  result.translation_condition = translationConditionNumber(D.hessian);
  result.cost = D.score;
  if (D.num_inliers == 0) {
    result.reason = "no source point falls into a target cell";
  } else if (!small_step) {
    result.reason =
        "no convergence within max_iterations (" + std::to_string(config.max_iterations) + ")";
  } else if (!std::isfinite(result.hessian_condition)) {
    result.reason = "Hessian not positive definite at the result (degenerate geometry)";
  } else if (result.translation_condition > config.max_translation_condition) {
    result.reason = "degenerate: a translation is poorly constrained (condition number " +
                    std::to_string(result.translation_condition) +
                    " of the Hessian's translation block)";
  } else {
    result.converged = true;
  }
  return result;
}

std::vector<double> resolutions(const NdtConfig& config) {
  std::vector<double> r = config.coarse_resolutions_m;
  std::sort(r.begin(), r.end(), std::greater<>());
  r.push_back(config.resolution_m);
  return r;
}

RegistrationResult failed(const lie::SE3& guess, std::string reason) {
  RegistrationResult r;
  r.T_target_source = guess;
  r.reason = std::move(reason);
  return r;
}

template <class AlignOne>
RegistrationResult coarseToFine(std::span<const Eigen::Vector3d> source,
                                std::span<const Eigen::Vector3d> target, const lie::SE3& guess,
                                const NdtConfig& config, const AlignOne& align_one) {
  config.validate();
  if (auto problem =
          inputProblem(target, "target", kMinSourcePoints, config.planar_eigenvalue_ratio)) {
    return failed(guess, *problem);
  }
  lie::SE3 T = guess;
  RegistrationResult result;
  int iterations = 0;
  for (double resolution : resolutions(config)) {
    const NdtTarget ndt_target =
        NdtTarget::fromPoints(target, resolution, config.cellsAt(resolution));
    result = align_one(source, ndt_target, T, config);
    iterations += result.iterations;
    if (result.num_inliers == 0) break;
    T = result.T_target_source;
  }
  result.iterations = iterations;
  return result;
}

}  // namespace

RegistrationResult alignNdt(std::span<const Eigen::Vector3d> source, const NdtTarget& target,
                            const lie::SE3& guess, const NdtConfig& config) {
  config.validate();
  if (auto problem =
          inputProblem(source, "source", kMinSourcePoints, config.planar_eigenvalue_ratio)) {
    return failed(guess, *problem);
  }
  if (target.empty()) {
    return failed(guess, "target has no NDT cell with at least " +
                             std::to_string(config.min_points_per_cell) + " points");
  }
  NeighbourCache cache(source.size());
  return newton(
      [&](const lie::SE3& T, bool with_hessian) {
        return ndtDerivatives(source, target, T, config, with_hessian, &cache);
      },
      guess, config, config.max_step_cells * target.resolution_m());
}

RegistrationResult alignNdt(std::span<const Eigen::Vector3d> source,
                            std::span<const Eigen::Vector3d> target, const lie::SE3& guess,
                            const NdtConfig& config) {
  return coarseToFine(source, target, guess, config,
                      [](auto s, const NdtTarget& t, const lie::SE3& g, const NdtConfig& c) {
                        return alignNdt(s, t, g, c);
                      });
}

RegistrationResult alignD2dNdt(std::span<const Eigen::Vector3d> source, const NdtTarget& target,
                               const lie::SE3& guess, const NdtConfig& config) {
  config.validate();
  if (auto problem =
          inputProblem(source, "source", kMinSourcePoints, config.planar_eigenvalue_ratio)) {
    return failed(guess, *problem);
  }
  if (target.empty()) {
    return failed(guess, "target has no NDT cell with at least " +
                             std::to_string(config.min_points_per_cell) + " points");
  }
  const D2dSource cells = makeD2dSource(source, config, target.resolution_m());
  if (cells.means.empty()) {
    return failed(guess, "source has no cell with at least " +
                             std::to_string(config.min_points_per_cell) + " points");
  }
  return newton(
      [&](const lie::SE3& T, bool with_hessian) {
        return d2dDerivatives(cells, target, T, config, with_hessian);
      },
      guess, config, config.max_step_cells * target.resolution_m());
}

RegistrationResult alignD2dNdt(std::span<const Eigen::Vector3d> source,
                               std::span<const Eigen::Vector3d> target, const lie::SE3& guess,
                               const NdtConfig& config) {
  return coarseToFine(source, target, guess, config,
                      [](auto s, const NdtTarget& t, const lie::SE3& g, const NdtConfig& c) {
                        return alignD2dNdt(s, t, g, c);
                      });
}

}  // namespace taiga::registration
