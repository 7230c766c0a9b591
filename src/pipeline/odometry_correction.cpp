#include "odometry_correction.hpp"

#include <cmath>
#include <stdexcept>

namespace taiga::pipeline {
namespace {

/// T with its rotation reduced to the turn about z, keeping where it maps `p_anchor`.
lie::SE3 turnAboutZ(const lie::SE3& T, const Eigen::Vector3d& p_anchor) {
  const lie::SO3 R_z = lie::SO3::fromRollPitchYaw(0.0, 0.0, T.rotation().yaw());
  return lie::SE3(R_z, T * p_anchor - R_z * p_anchor);
}

bool movedApart(const lie::SE3& a, const lie::SE3& b) {
  const lie::SE3 delta = a.inverse() * b;
  return delta.translation().norm() > OdometryCorrection::kMinShiftM ||
         delta.rotation().angle() > OdometryCorrection::kMinTurnRad;
}

}  // namespace

void OdometryCorrection::addKeyframe(std::uint64_t id, const lie::SE3& T_odom_keyframe) {
  if (id != T_odom_keyframes_.size())
    throw std::logic_error("OdometryCorrection: keyframes must arrive in id order");
  T_odom_keyframes_.push_back(T_odom_keyframe);
  local_map_.push_back({id, T_odom_keyframe});
  while (local_map_.size() > local_map_keyframes_) local_map_.pop_front();
}

bool OdometryCorrection::apply(const mapping::GraphSnapshot& snapshot, bool keep_gravity,
                               Odometry& odometry) {
  const std::size_t k = snapshot.keyframe;
  const std::size_t count = snapshot.poses_T_map_body.size();
  if (k >= T_odom_keyframes_.size() || count == 0 || count > k + 1)
    throw std::logic_error("OdometryCorrection: a snapshot of unknown keyframes");
  const lie::SE3& T_map_k = snapshot.poses_T_map_body.back();
  const lie::SE3& T_odom_k = T_odom_keyframes_[k];
  T_map_odom_ = T_map_k * T_odom_k.inverse();
  if (keep_gravity) T_map_odom_ = turnAboutZ(T_map_odom_, T_odom_k.translation());

  // The local map's keyframes up to k in the graph's shape, anchored at keyframe k.
  const lie::SE3 T_odom_map = T_odom_k * T_map_k.inverse();
  const std::size_t first_id = k + 1 - count;
  const std::size_t local_first_id = T_odom_keyframes_.size() - local_map_.size();
  bool bent = false;
  std::vector<lie::SE3> reshaped;
  for (std::size_t i = 0; i < local_map_.size(); ++i) {
    const std::size_t id = local_first_id + i;
    reshaped.push_back(id >= first_id && id <= k
                           ? T_odom_map * snapshot.poses_T_map_body[id - first_id]
                           : local_map_[i].T_odom_keyframe);
    bent = bent || movedApart(reshaped.back(), local_map_[i].T_odom_keyframe);
  }
  if (!bent) return false;
  for (std::size_t i = 0; i < local_map_.size(); ++i) local_map_[i].T_odom_keyframe = reshaped[i];
  odometry.reposeLocalMap([&](std::uint64_t id, const lie::SE3& T_old_keyframe) {
    for (const LocalMapKeyframe& keyframe : local_map_)
      if (keyframe.id == id) return keyframe.T_odom_keyframe;
    return T_old_keyframe;  // a keyframe the run did not store: as it is
  });
  return true;
}

}  // namespace taiga::pipeline
