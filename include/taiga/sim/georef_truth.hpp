#pragma once
// Where the simulated world frame lies in a projected CRS (EPSG:3067 ETRS-TM35FIN by default):
// the truth that georeferencing methods are scored against, written as georef_truth.yaml.

#include <Eigen/Core>
#include <string>

#include "taiga/sim/scenario.hpp"

namespace taiga::sim {

struct GeorefTruth {
  int epsg = 3067;
  std::string crs_name;
  double origin_latitude_deg = 0.0;   ///< world origin, geodetic (WGS84 = ETRS89 here)
  double origin_longitude_deg = 0.0;
  double origin_height_m = 0.0;       ///< ellipsoidal
  double origin_easting_m = 0.0;      ///< world origin in the grid
  double origin_northing_m = 0.0;
  double world_yaw_from_east_deg = 0.0;   ///< angle from local east to world x, counterclockwise
  double meridian_convergence_deg = 0.0;  ///< angle from grid easting to local east, ccw
  double yaw_grid_world_deg = 0.0;        ///< angle from grid easting to world x, ccw (the sum)
  double scale = 1.0;  ///< grid metres per world metre at the origin (point scale x height)
  /// [E, N, h, 1]^T = T_epsg_world [x, y, z, 1]^T: the tangent-plane approximation at the world
  /// origin (scale * Rz(yaw_grid_world) horizontally, heights unscaled); 0.2 mm off at 50 m from
  /// the origin, 1.8 mm at 150 m (tests/geo).
  Eigen::Matrix4d T_epsg_world = Eigen::Matrix4d::Identity();
};

/// The georeference of the world frame that `gnss` defines (origin, world_yaw_deg, georef_epsg).
/// InputError for an unknown EPSG code.
GeorefTruth georefTruth(const GnssParams& gnss);

}  // namespace taiga::sim
