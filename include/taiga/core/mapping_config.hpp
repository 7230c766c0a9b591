#pragma once
// Configuration of the mapping graph and its loop closures (issue 7, thesis 3.1.2 and Eq. 38).

#include "taiga/core/config.hpp"

namespace taiga {

struct MappingConfig final : ConfigSection {
  bool loop_closure = true;
  /// Feed the graph's corrections back into the running odometry: its published poses and its
  /// local map follow the corrected keyframe poses (pipeline/odometry_correction.hpp).
  bool correct_odometry = true;
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
  /// 25 is chi^2(6 dof) at 99.97 %; true loops measured up to 4.6 (bench/BENCHMARK.md), a false
  /// loop 1.5 m / 3 deg off after 200 m without an earlier loop at 46.8 (session 20).
  double loop_max_chi2 = 25.0;
  // Relocalization (mapping/relocalization.hpp): a map segment the odometry started after it was
  // lost is searched for in the map, within this window around its dead-reckoned pose.
  bool relocalization = true;
  double relocalization_search_m = 4.0;     ///< m, on each side, in x and in y
  double relocalization_search_deg = 45.0;  ///< deg of heading, on each side
  /// And wherever the stems of the segment's newest keyframes match the map's stems, within
  /// loop_max_search_radius_m (mapping/stem_constellation.hpp).
  bool relocalization_stems = true;
  // The tree map while the run goes (pipeline/online_trees.hpp, docs/trees.md): RUN/trees.csv.
  bool trees = false;
  // Odometry between consecutive keyframes: sigma = floor + per-metre growth * distance.
  double odometry_sigma_m = 0.002;
  double odometry_sigma_m_per_m = 0.003;
  double odometry_sigma_rad = 0.0002;
  double odometry_sigma_rad_per_m = 0.0005;
  // GNSS fixes as factors of the graph (issue 9, thesis Eq. 43; backend/gnss_factor.hpp), with
  // the map-to-ENU transform (yaw and translation) estimated alongside. Off by default: the
  // thesis found that fusing poor under-canopy GNSS can break the map. The receiver's settings
  // (gate, error correlation time, antenna lever arm) are the georef section's, one set for the
  // fusion and the post-fit (GeorefConfig).
  bool gnss_fusion = false;
  /// Huber kernel threshold, in sigmas of the fix's reported covariance (multipath jumps).
  double gnss_huber_sigmas = 3.0;
  /// GNSS factors enter the graph only once this many fixes spread over this distance (the
  /// yaw of T_enu_map must be observable); T_enu_map starts from the robust post-fit.
  int gnss_min_fixes = 5;
  double gnss_min_spread_m = 10.0;
  /// The graph is re-solved with new fixes at most once per this much recording time.
  double gnss_optimize_interval_s = 5.0;

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

}  // namespace taiga
