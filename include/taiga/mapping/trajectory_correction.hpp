#pragma once
// Carries the mapping graph's keyframe corrections over to every odometry pose. The correction
// of keyframe k is C_k = T_map_k * T_odom_k^-1 (a change of frame, odom to map, that moves the
// odometry's keyframe pose onto the optimized one); a pose at time t between keyframes k and k+1
// gets C interpolated on the SE(3) geodesic between C_k and C_k+1 (thesis Eq. 34's
// interpolation), before the first keyframe C_0 and after the last one C_last.

#include <vector>

#include "taiga/core/trajectory.hpp"
#include "taiga/mapping/pose_graph.hpp"

namespace taiga::mapping {

/// `keyframe_times_s[k]` is the time of graph keyframe k (increasing).
Trajectory correctedTrajectory(const Trajectory& odometry, const PoseGraph& graph,
                               const std::vector<double>& keyframe_times_s);

}  // namespace taiga::mapping
