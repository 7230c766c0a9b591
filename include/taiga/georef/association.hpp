#pragma once
// Association of local GNSS fixes with a trajectory T_world_body by time: the pose at a fix's
// time is interpolated on the SE(3) geodesic between the two neighbouring poses (thesis Eq. 34).
// Fixes before the first or after the last pose, and fixes in a gap (neighbouring poses further
// apart than max_gap_s), are dropped and counted: extrapolating a pose would invent data.

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "taiga/core/trajectory.hpp"
#include "taiga/georef/fix_preparation.hpp"

namespace taiga::georef {

struct AssociationOptions {
  /// Fixes between two poses more than this apart are dropped, s. Trajectories of taiga run
  /// have one pose per scan (0.1 s) or per IMU sample.
  double max_gap_s = 1.0;
  /// Antenna phase centre in the body frame, m (the lever arm). The fit relates the fixes to
  /// T_world_body * p_body_antenna.
  Eigen::Vector3d p_body_antenna = Eigen::Vector3d::Zero();
};

/// A fix with the trajectory's pose at its time.
struct AssociatedFix {
  LocalFix fix;
  lie::SE3 T_world_body;     ///< interpolated at fix.t_s
  Eigen::Vector3d p_world;   ///< the antenna in the world frame: T_world_body * p_body_antenna
};

struct Association {
  std::vector<AssociatedFix> pairs;  ///< in the fixes' order
  std::size_t outside_span = 0;      ///< fixes before the first or after the last pose
  std::size_t in_gap = 0;            ///< fixes between poses more than max_gap_s apart
};

/// Associates each fix with the pose at its time. `trajectory_world_body` must not be empty.
Association associateFixes(const Trajectory& trajectory_world_body,
                           const std::vector<LocalFix>& fixes, const AssociationOptions& options);

}  // namespace taiga::georef
