#include "taiga/preprocess/deskew.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

namespace taiga::preprocess {
namespace {

lie::SE3 clampedPoseAt(const Trajectory& trajectory, double t_s) {
  return trajectory.poseAt(std::clamp(t_s, trajectory.startTime(), trajectory.endTime()));
}

}  // namespace

DeskewedScan deskew(const PointCloud& cloud_in_lidar, const lie::SE3& T_body_lidar,
                    const Trajectory& trajectory_world_body, double t_ref_s) {
  if (!cloud_in_lidar.empty() && !cloud_in_lidar.hasTimes())
    throw std::invalid_argument("deskew: the cloud has no per-point times");
  if (trajectory_world_body.empty()) throw std::invalid_argument("deskew: empty trajectory");

  DeskewedScan result;
  result.t_ref_s = t_ref_s;
  result.cloud_in_body = cloud_in_lidar;

  std::vector<double> distinct_times = cloud_in_lidar.times_s;
  std::sort(distinct_times.begin(), distinct_times.end());
  distinct_times.erase(std::unique(distinct_times.begin(), distinct_times.end()),
                       distinct_times.end());

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
  for (std::size_t i = 0; i < cloud_in_lidar.size(); ++i) {
    const double t = cloud_in_lidar.times_s[i];
    const std::size_t k =
        std::lower_bound(distinct_times.begin(), distinct_times.end(), t) - distinct_times.begin();
    result.cloud_in_body.positions[i] =
        rotations[k] * cloud_in_lidar.positions[i] + translations[k];
    if (!trajectory_world_body.covers(t)) ++result.clamped_points;
  }
  return result;
}

}  // namespace taiga::preprocess
