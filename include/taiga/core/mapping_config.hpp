#pragma once
// Configuration of the mapping graph and its loop closures (issue 7, thesis 3.1.2 and Eq. 38).

#include "taiga/core/config.hpp"

namespace taiga {

struct MappingConfig final : ConfigSection {
  bool loop_closure = true;
  // Candidates (thesis Eq. 38): the nearest keyframe in space, excluding the most recent ones,
  // within a radius that grows with the path travelled since the candidate (the drift it may
  // have accumulated), so long loops still close.
  int loop_exclude_recent_keyframes = 40;
  double loop_search_radius_m = 5.0;
  double loop_radius_growth_m_per_m = 0.02;
  double loop_max_search_radius_m = 30.0;
  double loop_min_interval_s = 1.5;
  int loop_submap_keyframes = 10;  ///< keyframes on each side of the candidate in its submap
  // Verification: registration quality and consistency with the graph.
  double loop_max_fitness_m2 = 0.1;
  double loop_max_rotation_deg = 10.0;  ///< largest correction a loop may imply, besides the radius
  /// Consistency with the graph: a loop is kept when adding it raises the graph's optimal cost
  /// by at most this chi^2 (twice the cost change; the innovation's squared Mahalanobis distance).
  double loop_max_chi2 = 50.0;
  // Odometry between consecutive keyframes: sigma = floor + per-metre growth * distance.
  double odometry_sigma_m = 0.002;
  double odometry_sigma_m_per_m = 0.003;
  double odometry_sigma_rad = 0.0002;
  double odometry_sigma_rad_per_m = 0.0005;

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

}  // namespace taiga
