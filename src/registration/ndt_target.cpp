#include <Eigen/Eigenvalues>
#include <cmath>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taiga/registration/ndt.hpp"

namespace taiga::registration {

void NdtConfig::validate() const {
  auto fail = [](const std::string& field, const std::string& expected, double value) {
    throw std::invalid_argument("NdtConfig." + field + ": expected " + expected + ", got " +
                                std::to_string(value));
  };
  if (!(resolution_m > 0.0)) fail("resolution_m", "> 0 m", resolution_m);
  for (double r : coarse_resolutions_m) {
    if (!(r > resolution_m)) fail("coarse_resolutions_m", "values > resolution_m", r);
  }
  if (!(outlier_ratio > 0.0 && outlier_ratio < 1.0)) fail("outlier_ratio", "(0, 1)", outlier_ratio);
  if (min_points_per_cell < 3) {
    fail("min_points_per_cell", ">= 3", static_cast<double>(min_points_per_cell));
  }
  if (!(min_eigenvalue_ratio > 0.0 && min_eigenvalue_ratio <= 1.0)) {
    fail("min_eigenvalue_ratio", "(0, 1]", min_eigenvalue_ratio);
  }
  if (!(line_cell_ratio >= 0.0 && line_cell_ratio < 1.0)) {
    fail("line_cell_ratio", "[0, 1)", line_cell_ratio);
  }
  if (max_iterations < 1) fail("max_iterations", ">= 1", max_iterations);
  if (!(max_translation_condition >= 1.0)) {
    fail("max_translation_condition", ">= 1", max_translation_condition);
  }
  if (!(step_epsilon_m > 0.0)) fail("step_epsilon_m", "> 0 m", step_epsilon_m);
  if (!(step_epsilon_rad > 0.0)) fail("step_epsilon_rad", "> 0 rad", step_epsilon_rad);
  if (!(max_step_cells > 0.0)) fail("max_step_cells", "> 0", max_step_cells);
}

NdtConstants ndtConstants(double resolution_m, double outlier_ratio) {
  // Magnusson Eq. 6.8 (as in PCL and ndt_omp): c1, c2 make the mixture integrate to one over a
  // cell; d3 removes the constant so the score of a far-away point is zero.
  const double c1 = 10.0 * (1.0 - outlier_ratio);
  const double c2 = outlier_ratio / std::pow(resolution_m, 3);
  const double d3 = -std::log(c2);
  NdtConstants k;
  k.d1 = -std::log(c1 + c2) - d3;
  k.d2 = -2.0 * std::log((-std::log(c1 * std::exp(-0.5) + c2) - d3) / k.d1);
  return k;
}

namespace {

/// A cell whose own section did not make it a stem cell.
struct NotStem {
  std::size_t cell;
  const CellMoments* moments;
  double min_variance_m2;  ///< the floor of its Gaussian's eigenvalues
};

// A stem whose axis runs near a cell border leaves each cell a short arc that fails the gates,
// and those cells kept most of the remaining bias (docs/registration.md, "Local-map points on
// the surface, and stems across cell borders"). Each such cell tries the four 2 x 2 blocks of cells
// it belongs to and takes the circle of the block with the most points that passes.
void fitStemsAcrossBorders(std::span<const CellMoments> moments, std::span<const NotStem> not_stems,
                           double resolution_m, std::vector<NdtCell>& cells) {
  if (not_stems.empty()) return;
  std::vector<VoxelKey> keys;
  keys.reserve(moments.size());
  for (const CellMoments& m : moments) keys.push_back(m.key);
  const VoxelIndex index(keys);
  for (const NotStem& own : not_stems) {
    std::size_t best_count = 0;
    for (const VoxelKey corner :
         {VoxelKey{0}, -kVoxelStepX, -kVoxelStepY, -kVoxelStepX - kVoxelStepY}) {
      const CellMoments* block[4];
      std::size_t n = 0, count = 0;
      for (const VoxelKey step :
           {VoxelKey{0}, kVoxelStepX, kVoxelStepY, kVoxelStepX + kVoxelStepY}) {
        if (const std::int32_t j = index.find(own.moments->key + corner + step); j >= 0) {
          block[n++] = &moments[j];
          count += moments[j].count;
        }
      }
      if (n < 2 || count <= best_count) continue;
      if (fitStemSectionAcross(*own.moments, std::span(block, n), resolution_m, own.min_variance_m2,
                               cells[own.cell])) {
        best_count = count;
      }
    }
  }
}

}  // namespace

NdtTarget::NdtTarget(const VoxelStatistics& stats, const NdtConfig& cells)
    : resolution_m_(stats.resolution_m()), inverse_resolution_(1.0 / stats.resolution_m()) {
  if (cells.stem_cells && !stats.circleMoments()) {
    throw std::logic_error("NdtTarget: stem cells need statistics with circle moments");
  }
  const std::vector<CellMoments> moments = stats.moments(cells.min_points_per_cell);
  cells_.reserve(moments.size());
  keys_.reserve(moments.size());
  std::vector<NotStem> not_stems;
  for (const CellMoments& m : moments) {
    // Closed form (Eigen's computeDirect) rather than the iterative QR: most of the target's
    // build (local_map_bench: 10.4 -> 7.4-7.8 ms a keyframe). On the demo's 722 000 cells the
    // regularized inverse covariances of the two agree to 1e-11 relative at worst (two close
    // small eigenvalues), since the clamp below discards what the closed form loses of the
    // smallest eigenvalues (bench/BENCHMARK.md, "Session 68").
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(m.covariance);
    Eigen::Vector3d lambda = solver.eigenvalues();
    const double lambda_max = lambda.maxCoeff();
    if (!(lambda_max > 0.0)) continue;  // all points equal (after quantization)
    // Ascending eigenvalues: a small middle one means the points lie along a line. In a map of
    // few scans most such cells are one ring across the ground or a slope, and a ring keeps its
    // range from the sensor as the sensor moves: scored against it, the next scan's ring pulls
    // the pose back towards the map's viewpoint (16 beams: 2.4 m behind after 3 s of walking).
    if (lambda(1) < cells.line_cell_ratio * lambda_max) continue;
    lambda = lambda.cwiseMax(cells.min_eigenvalue_ratio * lambda_max);
    const Eigen::Matrix3d& V = solver.eigenvectors();
    NdtCell cell;
    cell.mean = m.mean;
    cell.count = m.count;
    cell.covariance = V * lambda.asDiagonal() * V.transpose();
    cell.inverse_covariance = V * lambda.cwiseInverse().asDiagonal() * V.transpose();
    const double min_variance_m2 = cells.min_eigenvalue_ratio * lambda_max;
    if (cells.stem_cells && !fitStemSection(m, resolution_m_, min_variance_m2, cell)) {
      not_stems.push_back({cells_.size(), &m, min_variance_m2});
    }
    cells_.push_back(cell);
    keys_.push_back(m.key);
  }
  index_ = VoxelIndex(keys_);
  if (cells.stem_cells_across_borders) {
    fitStemsAcrossBorders(moments, not_stems, resolution_m_, cells_);
  }
}

NdtTarget NdtTarget::fromPoints(std::span<const Eigen::Vector3d> points, double resolution_m,
                                const NdtConfig& cells) {
  VoxelStatistics stats(resolution_m, cells.stem_cells);
  stats.add(points);
  return NdtTarget(stats, cells);
}

int NdtTarget::neighboursOf(VoxelKey key, NeighbourSearch search, const NdtCell** out) const {
  if (key == kInvalidVoxel) return 0;
  int n = 0;
  if (const std::int32_t i = index_.find(key); i >= 0) out[n++] = &cells_[i];
  if (search == NeighbourSearch::kDirect7) {
    // A face neighbour differs by +-1 on one axis.
    constexpr VoxelKey kSteps[6] = {kVoxelStepX,  -kVoxelStepX, kVoxelStepY,
                                    -kVoxelStepY, kVoxelStepZ,  -kVoxelStepZ};
    for (const VoxelKey step : kSteps) {
      if (const std::int32_t i = index_.find(key + step); i >= 0) out[n++] = &cells_[i];
    }
  }
  return n;
}

}  // namespace taiga::registration
