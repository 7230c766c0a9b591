#include "taiga/registration/voxel_nearest.hpp"

#include <tsl/robin_map.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "agreement.hpp"
#include "taiga/core/hash.hpp"

namespace taiga::registration {
namespace {

// Cell borders are where floor(p / cell) changes, which rounding moves by a few ulps: distances
// to a cell's box are taken this much short, so no cell that could hold a nearer point is skipped.
constexpr double kMargin_m = 1e-6;

/// The squared distance as nanoflann's L2_Simple_Adaptor sums it (axis by axis), bit for bit.
double squaredDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double dx = a.x() - b.x(), dy = a.y() - b.y(), dz = a.z() - b.z();
  return dx * dx + dy * dy + dz * dz;
}

}  // namespace

VoxelNearest::VoxelNearest(std::span<const Eigen::Vector3d> points, double cell_m)
    : cell_m_(cell_m), inverse_cell_(1.0 / cell_m) {
  if (!(cell_m > 0.0) || !std::isfinite(cell_m))
    throw std::invalid_argument("VoxelNearest: cell_m must be positive, got " +
                                std::to_string(cell_m));
  // The cells in the order their first point comes, then the points scattered into them.
  constexpr std::uint32_t kOutside = std::numeric_limits<std::uint32_t>::max();
  tsl::robin_map<VoxelKey, std::uint32_t, MixedKeyHash> cell_of_key;
  cell_of_key.reserve(points.size() / 4 + 1);
  std::vector<VoxelKey> keys;
  std::vector<std::uint32_t> cell_of_point(points.size(), kOutside);
  std::vector<std::uint32_t> counts;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;  // never anyone's nearest
    const VoxelKey key = voxelOf(points[i], inverse_cell_);
    if (key == kInvalidVoxel) {
      throw std::invalid_argument(
          "VoxelNearest: a point lies beyond the grid's 1e6 cells from the origin (" +
          std::to_string(points[i].norm()) + " m at cells of " + std::to_string(cell_m) +
          " m): express the points in a local frame");
    }
    const auto [it, inserted] =
        cell_of_key.try_emplace(key, static_cast<std::uint32_t>(keys.size()));
    if (inserted) {
      keys.push_back(key);
      counts.push_back(0);
      const auto cell = unpackVoxel(key);
      for (int a = 0; a < 3; ++a) {
        low_[a] = keys.size() == 1 ? cell[a] : std::min(low_[a], cell[a]);
        high_[a] = keys.size() == 1 ? cell[a] : std::max(high_[a], cell[a]);
      }
    }
    cell_of_point[i] = it->second;
    ++counts[it->second];
  }
  begin_.assign(keys.size() + 1, 0);
  for (std::size_t c = 0; c < keys.size(); ++c) begin_[c + 1] = begin_[c] + counts[c];
  points_.resize(begin_.back());
  std::vector<std::uint32_t> next(begin_.begin(), begin_.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i)
    if (cell_of_point[i] != kOutside) points_[next[cell_of_point[i]]++] = points[i];
  index_ = VoxelIndex(keys);
}

bool VoxelNearest::nearestWithin(const Eigen::Vector3d& query, double max_distance_m,
                                 std::size_t& index, double& squared_distance_m2,
                                 std::size_t hint) const {
  if (points_.empty() || !query.allFinite()) return false;
  double bound_m2 = max_distance_m * max_distance_m;
  if (hint < points_.size()) bound_m2 = std::min(bound_m2, squaredDistance(query, points_[hint]));
  // As KdTree's: a point at exactly the bound is found.
  double best_m2 = std::nextafter(bound_m2, std::numeric_limits<double>::infinity());
  bool found = false;
  std::int64_t centre[3];
  for (int a = 0; a < 3; ++a) {
    const double s = std::floor(query[a] * inverse_cell_);
    // A query far outside the grid: start from its nearest cell of the grid's box.
    centre[a] = static_cast<std::int64_t>(
        std::clamp(s, static_cast<double>(low_[a]), static_cast<double>(high_[a])));
  }
  // Rings of cells around the centre cell (k: the Chebyshev distance in cells), nearest first.
  for (std::int64_t k = 0;; ++k) {
    // Only the cells that the ball of the current bound touches, within the grid.
    const double reach_m = std::sqrt(best_m2);
    std::int64_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = centre[a] - k;
      hi[a] = centre[a] + k;
      if (std::isfinite(reach_m)) {
        lo[a] = std::max(
            lo[a], static_cast<std::int64_t>(std::floor((query[a] - reach_m) * inverse_cell_)));
        hi[a] = std::min(
            hi[a], static_cast<std::int64_t>(std::floor((query[a] + reach_m) * inverse_cell_)));
      }
      lo[a] = std::max(lo[a], low_[a]);
      hi[a] = std::min(hi[a], high_[a]);
    }
    for (std::int64_t ix = lo[0]; ix <= hi[0]; ++ix) {
      const bool inner_x = std::abs(ix - centre[0]) < k;
      for (std::int64_t iy = lo[1]; iy <= hi[1]; ++iy) {
        // Inside the ring's x and y, only its two z faces belong to it.
        const bool inner_xy = inner_x && std::abs(iy - centre[1]) < k;
        const std::int64_t step = inner_xy ? 2 * k : 1;
        for (std::int64_t iz = inner_xy ? centre[2] - k : lo[2]; iz <= hi[2]; iz += step) {
          if (iz < lo[2]) continue;
          const std::int64_t cell_index[3] = {ix, iy, iz};
          double box_m2 = 0.0;
          for (int a = 0; a < 3; ++a) {
            const double low_m = static_cast<double>(cell_index[a]) * cell_m_;
            const double gap_m =
                std::max({0.0, low_m - query[a], query[a] - (low_m + cell_m_)}) - kMargin_m;
            if (gap_m > 0.0) box_m2 += gap_m * gap_m;
          }
          if (box_m2 >= best_m2) continue;
          const std::int32_t cell = index_.find(packVoxel(ix, iy, iz));
          if (cell < 0) continue;
          for (std::uint32_t i = begin_[cell]; i < begin_[cell + 1]; ++i) {
            const double d2 = squaredDistance(query, points_[i]);
            if (d2 < best_m2) {
              best_m2 = d2;
              index = i;
              found = true;
            }
          }
        }
      }
    }
    // Every cell beyond this ring lies at least this far from the query.
    double beyond_m = std::numeric_limits<double>::infinity();
    bool covers_grid = true;
    for (int a = 0; a < 3; ++a) {
      const double low_m = static_cast<double>(centre[a] - k) * cell_m_;
      const double high_m = static_cast<double>(centre[a] + k + 1) * cell_m_;
      beyond_m = std::min({beyond_m, query[a] - low_m, high_m - query[a]});
      covers_grid = covers_grid && centre[a] - k <= low_[a] && centre[a] + k >= high_[a];
    }
    beyond_m -= kMargin_m;
    if (covers_grid || (beyond_m > 0.0 && beyond_m * beyond_m >= best_m2)) break;
    // Or every cell within reach has been visited.
    bool covers_reach = std::isfinite(reach_m);
    for (int a = 0; a < 3 && covers_reach; ++a) {
      covers_reach =
          static_cast<double>(centre[a] - k) * cell_m_ <= query[a] - reach_m - kMargin_m &&
          static_cast<double>(centre[a] + k + 1) * cell_m_ >= query[a] + reach_m + kMargin_m;
    }
    if (covers_reach) break;
  }
  if (!found) return false;
  squared_distance_m2 = best_m2;
  return true;
}

Agreement agreement(std::span<const Eigen::Vector3d> source, const VoxelNearest& target,
                    const lie::SE3& T_target_source, double max_distance_m) {
  return detail::agreementWith(source, target, T_target_source, max_distance_m);
}

}  // namespace taiga::registration
