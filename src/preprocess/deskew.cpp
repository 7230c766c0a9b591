#include "taiga/preprocess/deskew.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <tsl/robin_map.h>

#include "taiga/core/hash.hpp"

namespace taiga::preprocess {
namespace {

lie::SE3 clampedPoseAt(const Trajectory& trajectory, double t_s) {
  return trajectory.poseAt(std::clamp(t_s, trajectory.startTime(), trajectory.endTime()));
}

}  // namespace

DeskewedScan deskew(PointCloud cloud_in_lidar, const lie::SE3& T_body_lidar,
                    const Trajectory& trajectory_world_body, double t_ref_s) {
  if (!cloud_in_lidar.empty() && !cloud_in_lidar.hasTimes())
    throw std::invalid_argument("deskew: the cloud has no per-point times");
  if (trajectory_world_body.empty()) throw std::invalid_argument("deskew: empty trajectory");

  DeskewedScan result;
  result.t_ref_s = t_ref_s;

  // Points share times (one per column, thesis Eq. 35): one pose per distinct time, found through
  // a hash map (sorting the times of 128k points cost more than the deskew itself). A column's
  // points usually come one after another, so the previous point's time is tried first.
  tsl::robin_map<std::uint64_t, std::uint32_t, MixedKeyHash> index_of_time;
  std::vector<double> distinct_times;
  std::vector<std::uint32_t> time_index(cloud_in_lidar.size());
  std::uint64_t previous_bits = 0;
  std::uint32_t previous_index = 0;
  for (std::size_t i = 0; i < cloud_in_lidar.size(); ++i) {
    const double t = cloud_in_lidar.times_s[i] + 0.0;  // + 0.0 turns -0 into +0
    const auto bits = std::bit_cast<std::uint64_t>(t);
    if (i == 0 || bits != previous_bits) {
      auto [it, inserted] =
          index_of_time.try_emplace(bits, static_cast<std::uint32_t>(distinct_times.size()));
      if (inserted) distinct_times.push_back(t);
      previous_bits = bits;
      previous_index = it->second;
    }
    time_index[i] = previous_index;
  }

  // T_bodyref_lidar(t) = T_world_body(t_ref)^-1 * T_world_body(t) * T_body_lidar, per distinct
  // time.
  const lie::SE3 T_bodyref_world = clampedPoseAt(trajectory_world_body, t_ref_s).inverse();
  std::vector<Eigen::Matrix3d> rotations(distinct_times.size());
  std::vector<Eigen::Vector3d> translations(distinct_times.size());
  for (std::size_t k = 0; k < distinct_times.size(); ++k) {
    const lie::SE3 T =
        T_bodyref_world * clampedPoseAt(trajectory_world_body, distinct_times[k]) * T_body_lidar;
    rotations[k] = T.rotation().matrix();
    translations[k] = T.translation();
  }
  std::vector<char> outside(distinct_times.size());
  for (std::size_t k = 0; k < distinct_times.size(); ++k)
    outside[k] = !trajectory_world_body.covers(distinct_times[k]);
  for (std::size_t i = 0; i < cloud_in_lidar.size(); ++i) {
    const std::uint32_t k = time_index[i];
    Eigen::Vector3d& p = cloud_in_lidar.positions[i];  // in the lidar frame, then in the body's
    p = rotations[k] * p + translations[k];
    result.clamped_points += outside[k];
  }
  result.cloud_in_body = std::move(cloud_in_lidar);
  return result;
}

}  // namespace taiga::preprocess
