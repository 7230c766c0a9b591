#include "odometry_correction.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace taiga::pipeline {
namespace {

/// T with its rotation reduced to the turn about z, keeping where it maps `p_anchor`.
lie::SE3 turnAboutZ(const lie::SE3& T, const Eigen::Vector3d& p_anchor) {
  const Eigen::Matrix3d R = T.rotation().matrix();
  const double yaw_rad = std::atan2(R(1, 0), R(0, 0));
  const lie::SO3 R_z = lie::SO3::fromRollPitchYaw(0.0, 0.0, yaw_rad);
  return lie::SE3(R_z, T * p_anchor - R_z * p_anchor);
}

}  // namespace

void OdometryCorrection::addKeyframe(double t_s, const lie::SE3& T_odom_keyframe) {
  keyframe_times_s_.push_back(t_s);
  T_odom_keyframes_.push_back(T_odom_keyframe);
}

void OdometryCorrection::changeOdomFrame(const lie::SE3& T_new_old) {
  if (!T_world_odom_.matrix().isIdentity())
    throw std::logic_error("OdometryCorrection: the odom frame changed after a correction");
  for (lie::SE3& T_odom_keyframe : T_odom_keyframes_) T_odom_keyframe = T_new_old * T_odom_keyframe;
}

std::optional<std::size_t> OdometryCorrection::keyframeAt(double t_s) const {
  const auto found = std::lower_bound(keyframe_times_s_.begin(), keyframe_times_s_.end(), t_s);
  if (found == keyframe_times_s_.end() || *found != t_s) return std::nullopt;
  return static_cast<std::size_t>(found - keyframe_times_s_.begin());
}

bool OdometryCorrection::apply(const mapping::GraphSnapshot& snapshot,
                               LidarInertialOdometry& odometry) {
  const std::size_t k = snapshot.keyframe;
  const std::size_t count = snapshot.poses_T_world_body.size();
  if (k >= T_odom_keyframes_.size() || count == 0 || count > k + 1)
    throw std::logic_error("OdometryCorrection: a snapshot of unknown keyframes");
  const lie::SE3& T_graph_k = snapshot.poses_T_world_body.back();
  const lie::SE3& T_odom_k = T_odom_keyframes_[k];
  lie::SE3 T_world_odom = T_graph_k * T_odom_k.inverse();
  if (!odometry.lidarOnly()) T_world_odom = turnAboutZ(T_world_odom, T_odom_k.translation());
  const lie::SE3 T_new_old = T_world_odom * T_world_odom_.inverse();
  const lie::Vector6 change = T_new_old.Log();
  if (T_new_old.translation().norm() < kMinShiftM && change.tail<3>().norm() < kMinTurnRad)
    return false;
  // Keyframes up to k in the graph's shape, anchored at keyframe k in the new live frame; the
  // later ones (and any not found) as the odometry made them.
  const lie::SE3 T_world_graph = T_world_odom * T_odom_k * T_graph_k.inverse();
  const std::size_t first = k + 1 - count;
  odometry.correctWorld(T_new_old, [&](double t_s, const lie::SE3& T_old_keyframe) {
    const std::optional<std::size_t> id = keyframeAt(t_s);
    if (!id) return T_new_old * T_old_keyframe;
    if (*id >= first && *id <= k) return T_world_graph * snapshot.poses_T_world_body[*id - first];
    return T_world_odom * T_odom_keyframes_[*id];
  });
  T_world_odom_ = T_world_odom;
  return true;
}

}  // namespace taiga::pipeline
