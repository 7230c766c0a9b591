#pragma once
// Feeds the mapping graph's corrections back into the running odometry (issue 7: "the local map
// is rebuilt from the corrected poses"; MappingConfig::correct_odometry).
//
// Frames as in ROS REP-105: the odometry runs in `odom`, continuous and gravity-aligned, the
// frame the mapping graph receives its keyframes in; the graph's corrected poses are in `map`.
// After the graph has handled keyframe k, its snapshot gives
//   - T_map_odom = T_map_k * T_odom_k^-1, with an IMU reduced to the turn about z and the
//     translation that still put keyframe k's position where the graph has it (the published
//     orientation keeps the IMU's roll and pitch). Live poses are published as
//     T_map_odom * T_odom_body (trajectory_online.tum).
//   - the local map's shape: keyframes up to k take the graph's relative poses, anchored at
//     keyframe k's odometry pose (T_odom_i = T_odom_k * T_map_k^-1 * T_map_i), the later ones
//     keep theirs. When that moves a local-map keyframe by more than kMinShiftM or kMinTurnRad,
//     the local map is rebuilt from these poses. A rigid correction alone (the usual case: a
//     loop moves the recent keyframes together) changes only T_map_odom and costs nothing.
//
// The odometry's state never jumps, so its IMU factors and the graph's odometry factors stay
// consistent. The snapshot of keyframe k is taken when keyframe k + kDelayKeyframes is made
// (waiting for the mapping thread if it is behind), so the result depends on the data only, not
// on timing.

#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/mapping/mapper.hpp"
#include "taiga/pipeline/odometry.hpp"

namespace taiga::pipeline {

class OdometryCorrection {
 public:
  /// Keyframes between the one made and the one whose graph snapshot is applied: the mapping
  /// thread handles a keyframe (and its loop closure attempt) while the odometry makes the next.
  static constexpr std::size_t kDelayKeyframes = 2;
  /// Smaller changes of a local-map keyframe's pose do not rebuild the local map.
  static constexpr double kMinShiftM = 0.005;
  static constexpr double kMinTurnRad = 0.0002;

  /// local_map_keyframes: OdometryConfig::local_map_keyframes.
  explicit OdometryCorrection(std::size_t local_map_keyframes)
      : local_map_keyframes_(local_map_keyframes) {}

  const lie::SE3& T_map_odom() const { return T_map_odom_; }
  /// Keyframe ids 0, 1, ... in order, at their pose in the odom frame.
  void addKeyframe(std::uint64_t id, const lie::SE3& T_odom_keyframe);
  /// Takes the graph's snapshot: updates T_map_odom and, when the graph bent the local map's
  /// keyframes, rebuilds the odometry's local map. Returns whether it did.
  bool apply(const mapping::GraphSnapshot& snapshot, bool keep_gravity, Odometry& odometry);

 private:
  struct LocalMapKeyframe {
    std::uint64_t id;
    lie::SE3 T_odom_keyframe;  ///< as the local map has it now
  };

  std::size_t local_map_keyframes_;
  lie::SE3 T_map_odom_;
  std::vector<lie::SE3> T_odom_keyframes_;  ///< as the odometry made them, by id
  std::deque<LocalMapKeyframe> local_map_;  ///< the newest local_map_keyframes, oldest first
};

}  // namespace taiga::pipeline
