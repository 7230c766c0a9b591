#include "taiga/preprocess/deskew.hpp"

#include <tsl/robin_map.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "taiga/core/hash.hpp"

namespace taiga::preprocess {
namespace {

lie::SE3 clampedPoseAt(const Trajectory& trajectory, double t_s) {
  return trajectory.poseAt(std::clamp(t_s, trajectory.startTime(), trajectory.endTime()));
}

// Points share times (one per column, thesis Eq. 35): one pose per distinct time. Returns each
// point's index into `distinct_times`. A hash map finds them (sorting the times of 128k points
// cost more than the deskew itself), but most points are settled by a guess checked bit for bit
// first: the previous point's time (a column's points one after another), the time last seen in
// the point's column (an organized cloud, published row by row as the Ouster driver does: there
// the map lookup per point was most of the deskew's time, perf), or the distinct time seen after
// the previous one.
std::vector<std::uint32_t> labelTimes(const PointCloud& cloud,
                                      std::vector<double>& distinct_times) {
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  tsl::robin_map<std::uint64_t, std::uint32_t, MixedKeyHash> index_of_time;
  std::vector<std::uint32_t> index_of_column;
  if (cloud.hasColumns() && !cloud.empty())
    index_of_column.assign(
        std::size_t{*std::max_element(cloud.columns.begin(), cloud.columns.end())} + 1, kNone);
  std::vector<std::uint32_t> time_index(cloud.size());
  std::uint32_t previous = kNone;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double t = cloud.times_s[i] + 0.0;  // + 0.0 turns -0 into +0
    const auto bits = std::bit_cast<std::uint64_t>(t);
    auto holds = [&](std::uint32_t k) {
      return k < distinct_times.size() && std::bit_cast<std::uint64_t>(distinct_times[k]) == bits;
    };
    std::uint32_t* column_guess =
        index_of_column.empty() ? nullptr : &index_of_column[cloud.columns[i]];
    std::uint32_t k = previous;
    if (!holds(k)) {
      if (column_guess && holds(*column_guess)) {
        k = *column_guess;
      } else if (holds(previous + 1)) {
        k = previous + 1;
      } else {
        auto [it, inserted] =
            index_of_time.try_emplace(bits, static_cast<std::uint32_t>(distinct_times.size()));
        if (inserted) distinct_times.push_back(t);
        k = it->second;
      }
    }
    if (column_guess) *column_guess = k;
    time_index[i] = previous = k;
  }
  return time_index;
}

}  // namespace

DeskewedScan deskew(PointCloud cloud_in_lidar, const lie::SE3& T_body_lidar,
                    const Trajectory& trajectory_world_body, double t_ref_s) {
  if (!cloud_in_lidar.empty() && !cloud_in_lidar.hasTimes())
    throw std::invalid_argument("deskew: the cloud has no per-point times");
  if (trajectory_world_body.empty()) throw std::invalid_argument("deskew: empty trajectory");

  DeskewedScan result;
  result.t_ref_s = t_ref_s;

  std::vector<double> distinct_times;
  const std::vector<std::uint32_t> time_index = labelTimes(cloud_in_lidar, distinct_times);

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
