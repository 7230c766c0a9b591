#pragma once
// A ground map registered to airborne laser scanning (issue 23, docs/georeferencing.md, "ALS"):
// national ALS (in Finland the whole country, 5 or more pulses per m^2, in ETRS-TM35FIN) places a
// map in the grid to decimetres whatever the canopy does to GNSS.
//
// The map sees the ground and the stems from below, the aircraft the ground between the crowns
// and the crowns from above; what both see is the terrain and the crowns' volume. So:
// 1. The map, thinned to 0.3 m, keeps its ground (within 0.3 m of the lowest point of its 1 m
//    cell) and crown points (more than 3 m above it): stems and shrubs the aircraft rarely sees.
// 2. Height: the median difference between the ALS's lowest points and the map's, cell by cell
//    (a GNSS height is metres off).
// 3. Heading and position: a correlative search (registration/correlative_search.hpp) of those
//    points against the voxels the ALS occupies, over the guess's uncertainty, coarse (2 m voxels,
//    1 m and 1 deg steps) then fine (1 m voxels, 0.25 m and 0.25 deg); the height again after it.
// 4. All six degrees of freedom: GICP of the same points to the ALS points from the best
//    candidate; the 1-sigma by a delete-a-group jackknife over the map's four quadrants (the
//    points' errors are correlated over metres, so the GICP Hessian's formal covariance would be
//    ten times too small).
// 5. Checks: the share of the map's points with an ALS point within 1 m (coverage, at least
//    0.7), and the best candidate more than 4 m or 4 deg from the best one against it
//    (ambiguity). A map the ALS does not cover, or an ambiguous search, is a failure with its
//    reason, never a pose.

#include <Eigen/Core>
#include <span>
#include <string>

#include "taiga/lie/se3.hpp"

namespace taiga::georef {

struct AlsRegistrationOptions {
  double search_xy_m = 8.0;        ///< half width of the position search around the guess
  double search_yaw_deg = 8.0;     ///< half width of the heading search
  /// Share of map points near an ALS point, at least. Right answers had 0.79-0.82 on simulated
  /// walks and strip roads, the one wrong answer seen 0.65 (a tilted `typical` harvester map,
  /// bench/BENCHMARK.md "Session 38"): a measured guess, not a calibrated test.
  double min_coverage = 0.7;
  double max_second_score = 0.98;  ///< the next distinct candidate's score / the best's, at most
};

struct AlsRegistration {
  bool ok = false;
  std::string reason;   ///< why not, when not ok
  lie::SE3 T_grid_map;  ///< the map in the grid (easting, northing, height), when ok
  /// 1-sigma: east, north, up (m), roll, pitch, yaw (rad) in the grid.
  Eigen::Matrix<double, 6, 1> sigma = Eigen::Matrix<double, 6, 1>::Zero();
  double coverage = 0.0;        ///< share of the map's points within 1 m of an ALS point
  double score = 0.0;           ///< the fine search's best score (share of points in ALS voxels)
  double second_score = 0.0;    ///< the best candidate's in another basin (4 m or 4 deg away)
  double height_shift_m = 0.0;  ///< step 2's correction of the guess's height
  std::size_t map_points = 0;   ///< used (ground and crowns, thinned)
  std::size_t als_points = 0;
};

/// `map_points` in the map frame; `als_points` in the grid; `guess` the map's pose in the grid
/// (T_grid_map) within the searched window. Deterministic.
AlsRegistration registerToAls(std::span<const Eigen::Vector3d> map_points,
                              std::span<const Eigen::Vector3d> als_points, const lie::SE3& guess,
                              const AlsRegistrationOptions& options = {});

}  // namespace taiga::georef
