#pragma once
// A registration case in a simulated forest, shared by tests/registration/forest_registration_test
// and bench/forest_registration_bench: a local map of 15 keyframes about 1 m apart along a
// simulated walk (each deskewed with the ground truth, in the world frame, voxelized at 0.2 m as
// the odometry's local map is), and the first scan at least 0.7 m past the last keyframe
// (deskewed with the truth, body frame at its end, voxelized at 0.4 m) with its true pose.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "taiga/core/trajectory.hpp"
#include "taiga/preprocess/deskew.hpp"
#include "taiga/preprocess/voxel_filter.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::test {

using Points = std::vector<Eigen::Vector3d>;

inline constexpr int kKeyframes = 15;
inline constexpr double kKeyframeSpacing_m = 1.0;
inline constexpr double kSourceBeyondLastKeyframe_m = 0.7;

struct ForestCase {
  Points map_points;  ///< world frame, 15 keyframes at 0.2 m
  Points source;      ///< body frame at the scan's end, 0.4 m
  lie::SE3 T_world_body;
  double source_to_last_keyframe_m = 0.0;
  double keyframe_span_m = 0.0;  ///< first to last keyframe, straight line
};

// The true T_world_body every millisecond over [t0 - 10 ms, t1 + 10 ms] (not before 0).
inline Trajectory truthAround(const sim::WalkingMotion& motion, double t0_s, double t1_s) {
  Trajectory trajectory;
  const double start = std::max(0.0, t0_s - 0.01);
  const int n = static_cast<int>(std::ceil((t1_s + 0.01 - start) / 0.001));
  for (int i = 0; i <= n; ++i) {
    const double t = start + 0.001 * i;
    trajectory.append(t, motion.at(t).T_world_body);
  }
  return trajectory;
}

// Scan `index` deskewed with the ground truth to the body frame at its end; the true pose there.
inline PointCloud deskewedScan(const sim::Simulation& simulation, std::uint64_t index,
                               lie::SE3* T_world_body_end) {
  const sim::LidarSimulator& lidar = simulation.lidar();
  const io::Scan scan = lidar.simulateScan(simulation.scene(), simulation.motion(), index,
                                           static_cast<double>(index) * lidar.scanPeriod_s());
  *T_world_body_end = simulation.motion().at(scan.t_end_s).T_world_body;
  const Trajectory truth = truthAround(simulation.motion(), scan.t_start_s, scan.t_end_s);
  return preprocess::deskew(scan.cloud_in_lidar, lidar.T_body_lidar(), truth, scan.t_end_s)
      .cloud_in_body;
}

// Keyframes from scan `first_scan` on, then the source scan, of one walk.
inline ForestCase makeForestCase(const sim::Simulation& simulation, std::uint64_t first_scan) {
  const sim::LidarSimulator& lidar = simulation.lidar();
  const double period = lidar.scanPeriod_s();
  // End time of scan i as the simulator fires it (last column), for choosing scans by the truth.
  const auto endOf = [&](std::uint64_t i) {
    return (static_cast<double>(i) + (lidar.columns() - 1.0) / lidar.columns()) * period;
  };
  const auto positionAt = [&](double t) {
    return simulation.motion().at(t).T_world_body.translation();
  };

  std::vector<std::uint64_t> keyframes = {first_scan};
  std::uint64_t i = first_scan + 1;
  for (; keyframes.size() < kKeyframes && i < simulation.scanCount(); ++i) {
    if ((positionAt(endOf(i)) - positionAt(endOf(keyframes.back()))).norm() >= kKeyframeSpacing_m)
      keyframes.push_back(i);
  }
  std::uint64_t source_index = i;
  while (source_index < simulation.scanCount() &&
         (positionAt(endOf(source_index)) - positionAt(endOf(keyframes.back()))).norm() <
             kSourceBeyondLastKeyframe_m) {
    ++source_index;
  }
  if (keyframes.size() < kKeyframes || source_index >= simulation.scanCount()) {
    throw std::runtime_error("the simulated walk is too short for 15 keyframes");
  }

  ForestCase out;
  for (const std::uint64_t k : keyframes) {
    lie::SE3 T_world_body;
    const PointCloud cloud =
        preprocess::voxelFilter(deskewedScan(simulation, k, &T_world_body), 0.2);
    for (const Eigen::Vector3d& p : cloud.positions) out.map_points.push_back(T_world_body * p);
  }
  out.source =
      preprocess::voxelFilter(deskewedScan(simulation, source_index, &out.T_world_body), 0.4)
          .positions;
  out.source_to_last_keyframe_m =
      (out.T_world_body.translation() - positionAt(endOf(keyframes.back()))).norm();
  out.keyframe_span_m =
      (positionAt(endOf(keyframes.back())) - positionAt(endOf(keyframes.front()))).norm();
  return out;
}

}  // namespace taiga::test
