#include "taiga/preprocess/voxel_filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <tsl/robin_map.h>

#include "taiga/core/hash.hpp"

namespace taiga::preprocess {
namespace {

/// Voxel coordinates packed into 64 bits, 21 bits per axis (+-1M voxels: +-400 km at 0.4 m).
std::uint64_t voxelKey(const Eigen::Vector3d& p, double inverse_size) {
  constexpr std::int64_t kBias = std::int64_t{1} << 20;
  constexpr std::int64_t kMask = (std::int64_t{1} << 21) - 1;
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const auto cell = static_cast<std::int64_t>(std::floor(p[axis] * inverse_size));
    key =
        (key << 21) | static_cast<std::uint64_t>(std::clamp<std::int64_t>(cell + kBias, 0, kMask));
  }
  return key;
}

}  // namespace

PointCloud voxelFilter(const PointCloud& cloud, double voxel_size_m,
                       VoxelRepresentative representative) {
  if (!(voxel_size_m > 0.0))
    throw std::invalid_argument("voxelFilter: voxel_size_m must be positive");
  const double inverse_size = 1.0 / voxel_size_m;

  // Points are gathered into cells through a hash map and only the cells are sorted by key: a
  // scan has 5-10 times more points than occupied voxels, and sorting the points was the cost.
  constexpr std::uint32_t kDropped = std::numeric_limits<std::uint32_t>::max();
  struct Cell {
    std::uint64_t key = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t count = 0;
    std::size_t nearest = 0;
    double nearest_d2 = std::numeric_limits<double>::infinity();
  };
  std::vector<Cell> cells;
  std::vector<std::uint32_t> cell_of_point(cloud.size(), kDropped);
  tsl::robin_map<std::uint64_t, std::uint32_t, MixedKeyHash> cell_of_key;
  // A spinning lidar's neighbouring returns (down a column) often share a voxel: the previous
  // point's cell is tried before the hash map.
  std::uint64_t previous_key = 0;
  std::uint32_t previous_cell = kDropped;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.positions[i];
    if (!p.allFinite()) continue;
    const std::uint64_t key = voxelKey(p, inverse_size);
    if (previous_cell == kDropped || key != previous_key) {
      auto [it, inserted] = cell_of_key.try_emplace(key, static_cast<std::uint32_t>(cells.size()));
      if (inserted) cells.push_back(Cell{key});
      previous_key = key;
      previous_cell = it->second;
    }
    Cell& cell = cells[previous_cell];
    cell.sum += p;  // in point order, as the sorted version summed them
    ++cell.count;
    cell_of_point[i] = previous_cell;
  }
  for (Cell& cell : cells) cell.sum /= static_cast<double>(cell.count);  // now the centroid
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (cell_of_point[i] == kDropped) continue;
    Cell& cell = cells[cell_of_point[i]];
    const double d2 = (cloud.positions[i] - cell.sum).squaredNorm();
    if (d2 < cell.nearest_d2) {  // ties keep the lowest index
      cell.nearest_d2 = d2;
      cell.nearest = i;
    }
  }
  // Keys are distinct, so the order is the same whatever is sorted; (key, cell) pairs move a
  // third of the bytes the cells would.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order(cells.size());
  for (std::size_t c = 0; c < cells.size(); ++c)
    order[c] = {cells[c].key, static_cast<std::uint32_t>(c)};
  std::sort(order.begin(), order.end());

  std::vector<Eigen::Vector3d> centroids;
  std::vector<std::size_t> representatives;
  centroids.reserve(cells.size());
  representatives.reserve(cells.size());
  for (const auto& [key, c] : order) {
    centroids.push_back(cells[c].sum);
    representatives.push_back(cells[c].nearest);
  }
  PointCloud filtered = cloud.select(representatives);  // positions: the nearest returns
  if (representative == VoxelRepresentative::centroid) filtered.positions = std::move(centroids);
  return filtered;
}

VoxelRepresentative voxelRepresentative(std::string_view name) {
  if (name == "centroid") return VoxelRepresentative::centroid;
  if (name == "measured") return VoxelRepresentative::measured;
  throw std::invalid_argument("voxel representative must be centroid or measured, not '" +
                              std::string(name) + "'");
}

}  // namespace taiga::preprocess
