#pragma once
// Motion compensation of a spinning-lidar scan (thesis Eq. 34-35): the sensor moves during the
// 100 ms sweep, so each point is moved into the body frame at one reference time with the body
// pose at its own firing time. Poses are interpolated on SE(3) once per distinct point time (one
// per column for a spinning lidar), not once per point.

#include <cstddef>

#include "taiga/core/point_cloud.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::preprocess {

struct DeskewedScan {
  PointCloud cloud_in_body;  ///< every point in the body frame at t_ref_s; channels kept
  double t_ref_s = 0.0;
  /// Points whose time lay outside the trajectory's span; they used the pose at the nearer end.
  std::size_t clamped_points = 0;
};

/// p_body(t_ref) = T_world_body(t_ref)^-1 * T_world_body(t_i) * T_body_lidar * p_lidar_i.
/// `cloud_in_lidar` must carry per-point times; `trajectory_world_body` must not be empty.
/// Throws std::invalid_argument otherwise.
/// The cloud is taken by value: a caller that no longer needs it moves it in, and its positions
/// are overwritten in place rather than copied.
DeskewedScan deskew(PointCloud cloud_in_lidar, const lie::SE3& T_body_lidar,
                    const Trajectory& trajectory_world_body, double t_ref_s);

}  // namespace taiga::preprocess
