#pragma once
// Nearest-point queries within a radius over points bucketed in a voxel grid: the same distances
// as KdTree::nearestWithin (exact, the squared distance summed axis by axis as nanoflann sums
// it), for a local map rebuilt at every keyframe. Bucketing the points costs one pass and no
// sort, where the kd-tree's build sorted and partitioned them (bench/local_map_bench).
//
// A query visits the cells that the ball of its bound touches, nearest first ring by ring, and
// stops when no unvisited cell can hold a nearer point. The bound starts at the radius, or at the
// distance of a hint point (the previous query's nearest, for queries in spatial order): then
// only the few cells within that distance are visited.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/registration/kdtree.hpp"
#include "taiga/registration/voxel_index.hpp"

namespace taiga::registration {

class VoxelNearest {
 public:
  /// The points (any order; kept bucketed by cell) in cells of `cell_m` (> 0) metres;
  /// non-finite points are left out. std::invalid_argument for a bad cell_m or a point more than
  /// 1e6 cells from the origin (a map in a projected CRS at small cells: use a local frame).
  VoxelNearest(std::span<const Eigen::Vector3d> points, double cell_m);

  std::size_t size() const { return points_.size(); }
  /// The points, bucketed by cell.
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  /// The nearest point within max_distance_m (inclusive), as KdTree::nearestWithin: `hint`, when
  /// not kNoHint, is an index into points() whose distance bounds the search.
  bool nearestWithin(const Eigen::Vector3d& query, double max_distance_m, std::size_t& index,
                     double& squared_distance_m2, std::size_t hint = kNoHint) const;
  static constexpr std::size_t kNoHint = static_cast<std::size_t>(-1);

 private:
  double cell_m_;
  double inverse_cell_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::uint32_t> begin_;  ///< cell i holds points_[begin_[i], begin_[i + 1])
  VoxelIndex index_;                  ///< cell key -> cell
  std::int64_t low_[3] = {0, 0, 0};   ///< the occupied cells' index range per axis
  std::int64_t high_[3] = {-1, -1, -1};
};

/// agreement() (kdtree.hpp) with the nearest points found in a VoxelNearest: the same figures.
Agreement agreement(std::span<const Eigen::Vector3d> source, const VoxelNearest& target,
                    const lie::SE3& T_target_source, double max_distance_m);

}  // namespace taiga::registration
