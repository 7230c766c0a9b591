#include "taiga/core/mapping_config.hpp"

namespace taiga {

void MappingConfig::visit(ConfigVisitor& v) {
  v.field("loop_closure", loop_closure,
          "search for loop closures and correct the keyframe poses with them");
  v.field("correct_odometry", correct_odometry,
          "feed the graph's corrections back into the running odometry: its live pose and local "
          "map follow the corrected keyframe poses (two keyframes later)");
  v.field("loop_exclude_recent_keyframes", loop_exclude_recent_keyframes,
          "keyframes, the most recent ones are never loop candidates (thesis: 40)");
  v.field("loop_search_radius_m", loop_search_radius_m,
          "m, search radius around the current keyframe (thesis: 5 m)");
  v.field("loop_radius_growth_m_per_m", loop_radius_growth_m_per_m,
          "m per m of path travelled since the candidate, added to the radius for the drift");
  v.field("loop_max_search_radius_m", loop_max_search_radius_m, "m, cap of the grown radius");
  v.field("loop_min_interval_s", loop_min_interval_s,
          "s, at most one loop closure attempt per this interval (thesis: 1.5 s)");
  v.field("loop_submap_keyframes", loop_submap_keyframes,
          "keyframes on each side of the candidate that form the map the scan is registered to");
  v.field("loop_max_fitness_m2", loop_max_fitness_m2,
          "m^2, loop registrations with a worse fitness are rejected");
  v.field("loop_max_rotation_deg", loop_max_rotation_deg,
          "deg, loops that would rotate the current keyframe further are rejected");
  v.field("loop_max_chi2", loop_max_chi2,
          "loops that raise the optimal cost of the graph by more (as chi^2: twice the cost "
          "change) disagree with the odometry and are rejected as false");
  v.field("relocalization", relocalization,
          "search for a new map segment (started after the track was lost) in the map, and "
          "re-attach it there");
  v.field("relocalization_search_m", relocalization_search_m,
          "m, the search reaches this far on each side of the dead-reckoned position, in x and y");
  v.field("relocalization_search_deg", relocalization_search_deg,
          "deg, and this far on each side of the dead-reckoned heading");
  v.field("relocalization_stems", relocalization_stems,
          "also search where the segment's stems match the map's stems (any heading, within "
          "loop_max_search_radius_m): dead reckoning after a long gap can be farther off than "
          "the window");
  v.field("trees", trees,
          "detect stems while the run goes and keep RUN/trees.csv up to date (docs/trees.md)");
  v.field("odometry_sigma_m", odometry_sigma_m,
          "m, sigma of the translation between consecutive keyframes, at zero distance");
  v.field("odometry_sigma_m_per_m", odometry_sigma_m_per_m,
          "m per m travelled between the keyframes, added to that sigma");
  v.field("odometry_sigma_rad", odometry_sigma_rad,
          "rad, sigma of the rotation between consecutive keyframes, at zero distance");
  v.field("odometry_sigma_rad_per_m", odometry_sigma_rad_per_m,
          "rad per m travelled between the keyframes, added to that sigma");
  v.field("gnss_fusion", gnss_fusion,
          "fuse GNSS fixes into the graph, estimating the map-to-ENU yaw and translation");
  v.field("gnss_huber_sigmas", gnss_huber_sigmas,
          "sigmas of the reported covariance beyond which a fix is down-weighted (Huber)");
  v.field("gnss_min_fixes", gnss_min_fixes,
          "fixes needed before GNSS factors enter the graph (the heading must be observable)");
  v.field("gnss_min_spread_m", gnss_min_spread_m,
          "m, horizontal extent of the track over those fixes needed before fusing");
  v.field("gnss_optimize_interval_s", gnss_optimize_interval_s,
          "s of recording time, at most one graph solve for new GNSS fixes per interval");
}

void MappingConfig::validate() const {
  requireInRange("loop_exclude_recent_keyframes", loop_exclude_recent_keyframes, 1, 100000,
                 "keyframes");
  requirePositive("loop_search_radius_m", loop_search_radius_m, "m");
  requireNonNegative("loop_radius_growth_m_per_m", loop_radius_growth_m_per_m, "m/m");
  requireInRange("loop_max_search_radius_m", loop_max_search_radius_m, loop_search_radius_m, 1000.0,
                 "m");
  requireNonNegative("loop_min_interval_s", loop_min_interval_s, "s");
  requireInRange("relocalization_search_m", relocalization_search_m, 0.0, 20.0, "m");
  requireInRange("relocalization_search_deg", relocalization_search_deg, 0.0, 180.0, "deg");
  requireInRange("loop_submap_keyframes", loop_submap_keyframes, 1, 100, "keyframes");
  requirePositive("loop_max_fitness_m2", loop_max_fitness_m2, "m^2");
  requireInRange("loop_max_rotation_deg", loop_max_rotation_deg, 0.1, 180.0, "deg");
  requirePositive("loop_max_chi2", loop_max_chi2, "");
  requirePositive("odometry_sigma_m", odometry_sigma_m, "m");
  requireNonNegative("odometry_sigma_m_per_m", odometry_sigma_m_per_m, "m/m");
  requirePositive("odometry_sigma_rad", odometry_sigma_rad, "rad");
  requireNonNegative("odometry_sigma_rad_per_m", odometry_sigma_rad_per_m, "rad/m");
  requirePositive("gnss_huber_sigmas", gnss_huber_sigmas, "sigmas");
  requireInRange("gnss_min_fixes", gnss_min_fixes, 3, 100000, "fixes");
  requireNonNegative("gnss_min_spread_m", gnss_min_spread_m, "m");
  requireNonNegative("gnss_optimize_interval_s", gnss_optimize_interval_s, "s");
}

}  // namespace taiga
