#pragma once
// Feeds the mapping graph's corrections back into the running odometry (issue 7: "the local map
// is rebuilt from the corrected poses"; MappingConfig::correct_odometry).
//
// Two world frames: `odom`, the continuous frame the odometry started in, in which the mapping
// graph receives its keyframes and in which trajectory_odometry.tum is written; and `world`, the
// odometry's live frame, which follows the graph. T_world_odom starts as the identity. When the
// graph has moved keyframe k off its odometry pose (a loop closure, GNSS), the live frame is
// re-anchored so that keyframe k sits where the graph puts it: T_world_odom = T_graph_k *
// T_odom_k^-1, reduced with an IMU to a turn about z and a translation (the live frame must keep
// gravity along -z; keyframe k's position is still met exactly). The local map's keyframes then
// take the graph's shape up to k, anchored at keyframe k, and the odometry's own poses after k.
//
// The snapshot of keyframe k is taken when keyframe k + kDelayKeyframes is made (waiting for the
// mapping thread if it is behind), so the result depends on the data only, not on timing.

#include <cstddef>
#include <optional>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/mapping/mapper.hpp"
#include "taiga/pipeline/lidar_inertial_odometry.hpp"

namespace taiga::pipeline {

class OdometryCorrection {
 public:
  /// Keyframes between the one made and the one whose graph snapshot is applied: the mapping
  /// thread handles a keyframe (and its loop closure attempt) while the odometry makes the next.
  static constexpr std::size_t kDelayKeyframes = 2;
  /// Smaller changes of the live frame are not applied (the local map rebuild costs a full
  /// build of the NDT target).
  static constexpr double kMinShiftM = 0.005;
  static constexpr double kMinTurnRad = 0.0002;

  const lie::SE3& T_world_odom() const { return T_world_odom_; }
  /// Keyframe ids 0, 1, ... in order, at their pose in the odom frame.
  void addKeyframe(double t_s, const lie::SE3& T_odom_keyframe);
  /// The odometry levelled its world frame (before any correction): T_new_old.
  void changeOdomFrame(const lie::SE3& T_new_old);
  /// Moves the odometry with the graph's snapshot; returns whether the change was large enough
  /// to apply.
  bool apply(const mapping::GraphSnapshot& snapshot, LidarInertialOdometry& odometry);

 private:
  /// The keyframe at exactly t_s (local-map keyframes carry the times they were made at).
  std::optional<std::size_t> keyframeAt(double t_s) const;

  lie::SE3 T_world_odom_;
  std::vector<double> keyframe_times_s_;
  std::vector<lie::SE3> T_odom_keyframes_;
};

}  // namespace taiga::pipeline
