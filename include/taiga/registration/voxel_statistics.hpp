#pragma once
// Incremental voxel statistics: per cell the count, the sum of points and the sum of their outer
// products, so that a keyframe's points can be added to and removed from a local map without
// rebuilding it. The NDT target (ndt.hpp) is built from these sums; VoxelMeans (voxel_means.hpp)
// keeps the counts and sums alone, for means.
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
//
// Points added with their beams (BeamNoise: the sensor's position and the range noise) also add
// the range noise's expected share of those moments, so that a circle fit can take it out
// (errors in variables): a point x = x0 + e u with e ~ N(0, s^2) along its horizontal beam u adds
// on average s^2 u u^T to x x^T, s^2 (|u|^2 x0 + 2 (u.x0) u) to x w and
// s^2 (4 (u.x0)^2 + 2 w0 |u|^2) + 3 s^4 |u|^4 to w^2. Unbiased estimates of these from the noisy
// x are summed (the w^2 term's plug-in is 3 s^4 |u|^4 too large, so that much is subtracted).
// Without it an arc seen from one side is fitted too small and too near its viewers: 1 cm of
// range noise on 120 deg of a 10 cm stem puts Taubin's centre 9.5 mm toward them, with it 0.4 mm
// (bench/BENCHMARK.md, "Session 66").

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
  /// The range noise's share of the horizontal covariance (m^2, 1/n) and of xw, yw, ww, from
  /// the points added with their beams (BeamNoise); zero for the others. The noise-free
  /// section's moments are the above minus these.
  Eigen::Matrix2d noise_xx = Eigen::Matrix2d::Zero();
  double noise_xw = 0.0, noise_yw = 0.0, noise_ww = 0.0;
};

/// The beams of points added together: the sensor position (in the points' frame) and the
/// range noise's 1-sigma, sigma_m + sigma_per_m x range.
struct BeamNoise {
  Eigen::Vector3d sensor = Eigen::Vector3d::Zero();
  double sigma_m = 0.0;
  double sigma_per_m = 0.0;
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
  /// Adds points with their beams: with circle_moments and a noise above zero, the noise's share
  /// of the section's moments is summed too (see above); otherwise the same as add(points).
  void add(std::span<const Eigen::Vector3d> points, const BeamNoise& beams);
  /// Removes points that were added before (the same coordinates). A point whose cell is empty
  /// throws std::logic_error (the statistics are then partially updated); a point that was never
  /// added but falls into an occupied cell cannot be detected and corrupts that cell's sums.
  void remove(std::span<const Eigen::Vector3d> points);
  /// Removes points added with these beams.
  void remove(std::span<const Eigen::Vector3d> points, const BeamNoise& beams);
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
    // The range noise's expected share of xx, xy, yy, xw, yw and ww, rounded to quanta.
    std::int64_t noise_xx = 0, noise_xy = 0, noise_yy = 0;
    Int128 noise_xw = 0, noise_yw = 0, noise_ww = 0;
    bool operator==(const CircleSums& o) const = default;
  };
  void update(const Eigen::Vector3d& p, int sign, const BeamNoise* beams);
  /// Adds (sign +1) or removes the range noise's share of point p (q: p about its cell centre, in
  /// quanta) to a cell's circle sums; nothing for a zero noise.
  static void addNoiseShare(const Eigen::Vector3d& p, const std::int64_t q[3],
                            const BeamNoise& beams, int sign, CircleSums& circle);
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

}  // namespace taiga::registration
