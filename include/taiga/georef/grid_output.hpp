#pragma once
// A georeferenced trajectory in a projected CRS (EPSG code), computed exactly per pose:
// p_world -> T_enu_world -> local ENU at the origin -> geodetic (through ECEF) -> grid, so the
// result has no tangent-plane error however large the area. The grid yaw of the body's x axis
// adds the meridian convergence at the pose (GridTangent::yaw_deg) to the ENU yaw.
//
// The tangent-plane approximation T_epsg_world = T_grid_enu(origin) * T_enu_world (scale and
// convergence at the origin, heights unscaled) is also given, for users who want one matrix; it
// is off by millimetres at 150 m from the origin (geo/coordinates.hpp).

#include <Eigen/Core>
#include <vector>

#include "taiga/core/trajectory.hpp"
#include "taiga/geo/coordinates.hpp"

namespace taiga::georef {

struct GridPose {
  double t_s = 0.0;
  double easting_m = 0.0;
  double northing_m = 0.0;
  double height_m = 0.0;      ///< ellipsoidal
  double yaw_grid_deg = 0.0;  ///< body x axis from grid easting, counterclockwise, (-180, 180]
};

std::vector<GridPose> trajectoryInGrid(const Trajectory& trajectory_world_body,
                                       const lie::SE3& T_enu_world, const geo::Geodetic& origin,
                                       const geo::CoordinateConverter& converter);

/// The tangent-plane approximation [E, N, h, 1]^T = T_epsg_world [x, y, z, 1]^T.
Eigen::Matrix4d tangentPlaneEpsgWorld(const lie::SE3& T_enu_world, const geo::Geodetic& origin,
                                      const geo::CoordinateConverter& converter);

}  // namespace taiga::georef
