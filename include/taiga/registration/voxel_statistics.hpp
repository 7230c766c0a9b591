#pragma once
// Incremental voxel statistics: per cell the count, the sum of points and the sum of their outer
// products, so that a keyframe's points can be added to and removed from a local map without
// rebuilding it. The NDT target (ndt.hpp) and voxel downsampling are built from these sums.
//
// Sums are kept as integers: each point is quantized to kQuantum_m (10 um) relative to the centre
// of its cell. Adding and then removing the same points therefore restores the statistics exactly,
// bit for bit, and the result does not depend on the order in which points were added. The
// quantization changes a mean by at most 5 um. Limits: at cells of R m a cell holds up to
// 3.7e9 / R^2 points before the 64-bit square sums could overflow.
//
// On request (`circle_moments`), the horizontal section's higher moments that a circle fit needs
// (the sums of x w, y w and w^2 with w = x^2 + y^2; ndt.hpp, "Stem cells"), as 128-bit integers
// of the same quanta: exact as well. They are kept beside the other sums, so that statistics
// without them cost nothing more.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <tsl/robin_map.h>
#include <vector>

#include "taiga/core/hash.hpp"
#include "taiga/registration/voxel_index.hpp"

namespace taiga::registration {

__extension__ using Int128 = __int128;  ///< GCC's and Clang's 128-bit integer

/// Moments of one cell.
struct CellMoments {
  VoxelKey key = kInvalidVoxel;
  std::size_t count = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();        ///< m, in the frame of the points
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< m^2, unbiased (n - 1); 0 if n < 2
  /// The horizontal section's central moments a circle fit needs, with x, y about the mean and
  /// w = x^2 + y^2 (1/n): E[x w], E[y w] in m^3 and E[w^2] in m^4. Zero without circle_moments.
  double xw = 0.0, yw = 0.0, ww = 0.0;
};

class VoxelStatistics {
 public:
  static constexpr double kQuantum_m = 1e-5;

  /// Cells of `resolution_m` (> 0) metres; throws std::invalid_argument otherwise. With
  /// `circle_moments`, CellMoments::xw, yw and ww are kept too.
  explicit VoxelStatistics(double resolution_m, bool circle_moments = false);

  double resolution_m() const { return resolution_m_; }
  bool circleMoments() const { return circle_moments_; }
  /// Adds points (non-finite points and points beyond the voxel range are skipped and counted).
  void add(std::span<const Eigen::Vector3d> points);
  /// Removes points that were added before (the same coordinates). A point whose cell is empty
  /// throws std::logic_error (the statistics are then partially updated); a point that was never
  /// added but falls into an occupied cell cannot be detected and corrupts that cell's sums.
  void remove(std::span<const Eigen::Vector3d> points);
  void clear() {
    cells_.clear();
    circle_cells_.clear();
  }

  std::size_t numCells() const { return cells_.size(); }
  std::size_t numPoints() const;
  std::size_t numSkipped() const { return skipped_; }
  /// Moments of every cell with at least `min_points` points, sorted by voxel key (so the order
  /// is deterministic).
  std::vector<CellMoments> moments(std::size_t min_points = 1) const;
  /// Cell means of every occupied cell, in key order: a voxel-grid downsampling.
  std::vector<Eigen::Vector3d> means() const;

  /// Exact equality of the sums (the same cells with the same integer sums).
  bool operator==(const VoxelStatistics& other) const;

 private:
  struct Sums {
    std::int64_t count = 0;
    std::int64_t s[3] = {0, 0, 0};
    std::int64_t ss[6] = {0, 0, 0, 0, 0, 0};  ///< xx xy xz yy yz zz
    bool operator==(const Sums& o) const;
  };
  struct CircleSums {
    Int128 xw = 0, yw = 0, ww = 0;  ///< w = x^2 + y^2
    bool operator==(const CircleSums& o) const = default;
  };
  void update(const Eigen::Vector3d& p, int sign);
  Eigen::Vector3d meanOf(VoxelKey key, const Sums& sums) const;
  CellMoments momentsOf(VoxelKey key, const Sums& sums) const;
  static void circleMoments(const Sums& sums, const CircleSums& circle, CellMoments& m);

  double resolution_m_;
  double inverse_resolution_;
  std::size_t skipped_ = 0;
  /// Open addressing (robin hood): iterating and updating cells stays in contiguous memory,
  /// which made rebuilding the local map 2-3x faster than std::unordered_map.
  tsl::robin_map<VoxelKey, Sums, MixedKeyHash> cells_;
  bool circle_moments_ = false;
  tsl::robin_map<VoxelKey, CircleSums, MixedKeyHash> circle_cells_;  ///< with circle_moments
};

/// Voxel-grid downsampling: one point (the mean) per occupied cell of `leaf_m`, in key order.
std::vector<Eigen::Vector3d> voxelDownsample(std::span<const Eigen::Vector3d> points,
                                             double leaf_m);

}  // namespace taiga::registration
