#pragma once
// Registration without a trustworthy guess: from several headings, and an honest verdict.
//
// A local method (NDT, GICP) converges to the nearest basin; from a guess 40 deg off it can
// settle in a wrong one and still report convergence. Here the registration starts from
// `hypotheses` guesses spread evenly in yaw about the given one (a ground vehicle or a handheld
// rig turns mostly about the vertical), each solution is scored by its overlap (the share of
// source points within `inlier_distance_m` of the target) and the best one is kept. When a
// second, distinct solution (farther than distinct_m / distinct_deg) overlaps nearly as well
// (at least `ambiguity_ratio` of the best), the answer is ambiguous: reported as not converged.

#include <span>
#include <string>

#include "taiga/registration/registration.hpp"

namespace taiga::registration {

struct YawSearchOptions {
  int hypotheses = 12;  ///< guesses, 360 / hypotheses deg apart; 1: the guess alone
  double inlier_distance_m = 0.5;
  double ambiguity_ratio = 0.9;
  double distinct_m = 0.3;
  double distinct_deg = 3.0;
};

struct YawSearchResult {
  RegistrationResult best;  ///< converged = false when ambiguous
  double overlap = 0.0;     ///< the best solution's share of source points on the target
  bool ambiguous = false;
  /// The best distinct rival's overlap and its distance from the best (0 without one).
  double rival_overlap = 0.0, rival_m = 0.0, rival_deg = 0.0;
  int hypotheses = 1;
};

YawSearchResult registerWithYawSearch(std::span<const Eigen::Vector3d> source,
                                      std::span<const Eigen::Vector3d> target,
                                      const lie::SE3& guess_T_target_source,
                                      const RegistrationConfig& config,
                                      const YawSearchOptions& options = {});

}  // namespace taiga::registration
