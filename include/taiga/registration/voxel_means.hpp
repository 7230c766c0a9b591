#pragma once
// Incremental voxel means: per cell the count and the sum of its points, quantized as
// VoxelStatistics quantizes them (integers of 10 um about the cell centre), so that points can be
// added and removed again exactly and a cell's mean is the one VoxelStatistics gives, bit for
// bit. Without the second moments a cell takes a third of VoxelStatistics' memory: the local
// map's 0.2 m points, about 116 000 cells on the demo, are updated at every keyframe, and their
// table's cache misses were most of the update (bench/local_map_bench, bench/BENCHMARK.md
// "Session 68").

#include <tsl/robin_map.h>

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "taiga/core/hash.hpp"
#include "taiga/registration/voxel_index.hpp"

namespace taiga::registration {

class VoxelMeans {
 public:
  /// Cells of `resolution_m` (> 0) metres; throws std::invalid_argument otherwise.
  explicit VoxelMeans(double resolution_m);

  double resolution_m() const { return resolution_m_; }
  /// Adds points (non-finite points and points beyond the voxel range are skipped and counted).
  void add(std::span<const Eigen::Vector3d> points);
  /// Removes points added before (the same coordinates); a point whose cell is empty throws
  /// std::logic_error (the means are then partially updated).
  void remove(std::span<const Eigen::Vector3d> points);
  void clear() { cells_.clear(); }

  std::size_t numCells() const { return cells_.size(); }
  std::size_t numPoints() const;
  std::size_t numSkipped() const { return skipped_; }
  /// Every occupied cell's mean, in key order: a voxel-grid downsampling.
  std::vector<Eigen::Vector3d> means() const;
  /// The same means in the hash table's order, which depends only on the sequence of adds and
  /// removes: for a structure that orders them itself, without the sort.
  std::vector<Eigen::Vector3d> meansInTableOrder() const;

 private:
  struct Sums {
    std::int64_t count = 0;
    std::int64_t s[3] = {0, 0, 0};
  };
  void update(const Eigen::Vector3d& p, int sign);

  double resolution_m_;
  double inverse_resolution_;
  std::size_t skipped_ = 0;
  tsl::robin_map<VoxelKey, Sums, MixedKeyHash> cells_;
};

/// Voxel-grid downsampling: one point (the mean) per occupied cell of `leaf_m`, in key order.
std::vector<Eigen::Vector3d> voxelDownsample(std::span<const Eigen::Vector3d> points,
                                             double leaf_m);

}  // namespace taiga::registration
