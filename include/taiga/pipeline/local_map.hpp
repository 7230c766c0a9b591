#pragma once
// The local map that scans are registered to: the points of the latest keyframes in the world
// frame. Its NDT cells come from incremental voxel statistics, so adding a keyframe and dropping
// the oldest costs only their own points (registration/voxel_statistics.hpp); the search
// structures are rebuilt lazily, once per change, not once per scan, over the deduplicated points.

#include <Eigen/Core>
#include <deque>
#include <memory>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/registration/gicp.hpp"
#include "taiga/registration/kdtree.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::pipeline {

class LocalMap {
 public:
  /// NDT cells of ndt_resolution_m; the kd-tree (fitness, GICP) over one point per
  /// point_spacing_m voxel, so overlapping keyframes do not multiply its size.
  LocalMap(double ndt_resolution_m, double point_spacing_m, int max_keyframes,
           const registration::GicpConfig& gicp = {});

  /// Adds one keyframe's points (world frame); drops the oldest keyframe beyond max_keyframes.
  void addKeyframe(std::vector<Eigen::Vector3d> points_in_world);
  /// Moves every point by T_new_old (a change of world frame, e.g. levelling).
  void transform(const lie::SE3& T_new_old);
  bool empty() const { return keyframes_.empty(); }
  std::size_t numKeyframes() const { return keyframes_.size(); }
  std::size_t numPoints() const;

  const registration::NdtTarget& ndtTarget();
  const registration::KdTree& kdTree();
  const registration::GicpCloud& gicpCloud();

 private:
  int max_keyframes_;
  registration::GicpConfig gicp_config_;
  std::deque<std::vector<Eigen::Vector3d>> keyframes_;
  registration::VoxelStatistics statistics_;        ///< NDT cells
  registration::VoxelStatistics point_statistics_;  ///< one mean per point_spacing_m voxel
  std::unique_ptr<registration::NdtTarget> ndt_target_;
  std::unique_ptr<registration::KdTree> kd_tree_;
  std::unique_ptr<registration::GicpCloud> gicp_cloud_;
};

}  // namespace taiga::pipeline
