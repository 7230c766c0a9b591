#include "taiga/registration/yaw_search.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "taiga/registration/kdtree.hpp"

namespace taiga::registration {
namespace {

struct Solution {
  RegistrationResult result;
  Agreement agreement;
};

}  // namespace

YawSearchResult registerWithYawSearch(std::span<const Eigen::Vector3d> source,
                                      std::span<const Eigen::Vector3d> target,
                                      const lie::SE3& guess_T_target_source,
                                      const RegistrationConfig& config,
                                      const YawSearchOptions& options) {
  const KdTree target_tree(target);
  RegistrationConfig local = config;
  local.compute_fitness = false;
  std::vector<Solution> solutions;
  const int n = std::max(1, options.hypotheses);
  for (int k = 0; k < n; ++k) {
    // Turned about the target's vertical through the guess's position.
    const double yaw_rad = 2.0 * std::numbers::pi * k / n;
    const lie::SE3 turn(lie::SO3::fromRollPitchYaw(0.0, 0.0, yaw_rad), Eigen::Vector3d::Zero());
    const lie::SE3 guess(turn.rotation() * guess_T_target_source.rotation(),
                         guess_T_target_source.translation());
    Solution s;
    s.result = registerClouds(source, target, guess, local);
    s.agreement =
        agreement(source, target_tree, s.result.T_target_source, options.inlier_distance_m);
    solutions.push_back(std::move(s));
  }
  // The best overlap; ties to the lower fitness.
  std::size_t best = 0;
  for (std::size_t i = 1; i < solutions.size(); ++i) {
    const Agreement& a = solutions[i].agreement;
    const Agreement& b = solutions[best].agreement;
    if (a.share > b.share || (a.share == b.share && a.fitness_m2 < b.fitness_m2)) best = i;
  }
  YawSearchResult out;
  out.hypotheses = n;
  out.best = solutions[best].result;
  out.overlap = solutions[best].agreement.share;
  for (const Solution& s : solutions) {
    const auto [m, deg] = separation(out.best.T_target_source, s.result.T_target_source);
    const bool distinct = m > options.distinct_m || deg > options.distinct_deg;
    if (distinct && s.agreement.share > out.rival_overlap) {
      out.rival_overlap = s.agreement.share;
      out.rival_m = m;
      out.rival_deg = deg;
    }
  }
  out.ambiguous = out.rival_overlap >= options.ambiguity_ratio * out.overlap && out.overlap > 0.0;
  if (out.ambiguous) {
    out.best.converged = false;
    out.best.reason = fmt::format(
        "ambiguous: a solution {:.2f} m / {:.1f} deg away overlaps {:.0f} % against {:.0f} %",
        out.rival_m, out.rival_deg, 100.0 * out.rival_overlap, 100.0 * out.overlap);
  }
  out.best.fitness_m2 = fitnessScore(source, target_tree, out.best.T_target_source);
  return out;
}

}  // namespace taiga::registration
