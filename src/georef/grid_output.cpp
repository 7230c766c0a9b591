#include "taiga/georef/grid_output.hpp"

#include <cmath>

#include "taiga/core/angles.hpp"

namespace taiga::georef {
namespace {

/// Wraps an angle in degrees into (-180, 180].
double wrapDegrees(double angle_deg) {
  double wrapped = std::fmod(angle_deg, 360.0);
  if (wrapped <= -180.0) wrapped += 360.0;
  if (wrapped > 180.0) wrapped -= 360.0;
  return wrapped;
}
}  // namespace

std::vector<GridPose> trajectoryInGrid(const Trajectory& trajectory_world_body,
                                       const lie::SE3& T_enu_world, const geo::Geodetic& origin,
                                       const geo::CoordinateConverter& converter) {
  std::vector<GridPose> grid;
  grid.reserve(trajectory_world_body.size());
  for (const StampedPose& pose : trajectory_world_body) {
    const lie::SE3 T_enu_body = T_enu_world * pose.pose;
    const geo::Geodetic point = converter.fromEnu(origin, T_enu_body.translation());
    const Eigen::Vector3d grid_position = converter.toProjected(point);
    // Grid yaw of the body x axis: the direction in the grid of a +-1 m step along the axis's
    // horizontal part (central difference through the exact conversion), which includes the
    // meridian convergence at the pose and the turn of the local ENU frame against the origin's.
    Eigen::Vector3d step_enu = T_enu_body.rotation().matrix().col(0);
    step_enu.z() = 0.0;
    if (step_enu.norm() < 1e-9) step_enu = Eigen::Vector3d::UnitX();  // x axis vertical
    step_enu.normalize();
    const Eigen::Vector3d ahead =
        converter.toProjected(converter.fromEnu(origin, T_enu_body.translation() + step_enu));
    const Eigen::Vector3d behind =
        converter.toProjected(converter.fromEnu(origin, T_enu_body.translation() - step_enu));
    const double yaw_grid_deg =
        std::atan2(ahead.y() - behind.y(), ahead.x() - behind.x()) * kDegPerRad;
    grid.push_back({pose.t_s, grid_position.x(), grid_position.y(), grid_position.z(),
                    wrapDegrees(yaw_grid_deg)});
  }
  return grid;
}

Eigen::Matrix4d tangentPlaneEpsgWorld(const lie::SE3& T_enu_world, const geo::Geodetic& origin,
                                      const geo::CoordinateConverter& converter) {
  return converter.gridTangent(origin).T_grid_enu * T_enu_world.matrix();
}

}  // namespace taiga::georef
