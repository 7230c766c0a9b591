#include "taiga/preprocess/voxel_filter.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tsl/robin_map.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "taiga/core/hash.hpp"
#include "taiga/core/radix_sort.hpp"

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

constexpr std::uint64_t kNoKey = std::numeric_limits<std::uint64_t>::max();  // a NaN point

/// The cells of the voxels whose keys fall into one partition. Every voxel belongs to exactly
/// one partition and each partition visits its points in index order, so a cell's sum and its
/// nearest point are the same, bit for bit, whatever the number of partitions or threads.
class Partition {
 public:
  struct Cell {
    std::uint64_t key = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();  ///< then the centroid
    std::size_t count = 0;
    std::size_t nearest = 0;
    double nearest_d2 = std::numeric_limits<double>::infinity();
  };
  static constexpr unsigned kCount = 4;  ///< partitions: enough for the cores of a small PC
  static unsigned of(std::uint64_t key) {
    return static_cast<unsigned>(MixedKeyHash{}(key) >> 62);  // top bits: the map uses the low
  }

  /// `parts[i]`: the partition of point i (kCount for a NaN point).
  /// With `sensor`, a cell's nearest point is the one nearest the centroid in direction from it.
  void gather(const std::vector<Eigen::Vector3d>& positions, const std::vector<std::uint64_t>& keys,
              const std::vector<std::uint8_t>& parts, unsigned part,
              const Eigen::Vector3d* sensor) {
    // My points in index order, compacted without a branch: which partition a point falls into
    // is random, and a branch on it was mispredicted about every other point (a quarter of the
    // filter's time, perf).
    std::vector<std::uint32_t> mine(keys.size());
    std::size_t n = 0;
    for (std::size_t i = 0; i < keys.size(); ++i) {
      mine[n] = static_cast<std::uint32_t>(i);
      n += parts[i] == part ? 1 : 0;
    }
    mine.resize(n);
    std::vector<std::uint32_t> cell_of_mine(n);  // the cell of each of my points
    tsl::robin_map<std::uint64_t, std::uint32_t, MixedKeyHash> cell_of_key;
    cell_of_key.reserve(n / 4);  // a scan has 2-8 points per voxel
    // A spinning lidar's neighbouring returns (down a column) often share a voxel: the previous
    // point's cell is tried before the hash map.
    std::uint64_t previous_key = kNoKey;
    std::uint32_t previous_cell = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint64_t key = keys[mine[k]];
      if (key != previous_key) {
        auto [it, inserted] =
            cell_of_key.try_emplace(key, static_cast<std::uint32_t>(cells.size()));
        if (inserted) cells.push_back(Cell{key});
        previous_key = key;
        previous_cell = it->second;
      }
      Cell& cell = cells[previous_cell];
      cell.sum += positions[mine[k]];  // in point order
      ++cell.count;
      cell_of_mine[k] = previous_cell;
    }
    for (Cell& cell : cells) cell.sum /= static_cast<double>(cell.count);
    std::vector<Eigen::Vector3d> centroid_bearings;
    if (sensor != nullptr) {
      centroid_bearings.reserve(cells.size());
      for (const Cell& cell : cells) centroid_bearings.push_back((cell.sum - *sensor).normalized());
    }
    for (std::size_t k = 0; k < mine.size(); ++k) {
      Cell& cell = cells[cell_of_mine[k]];
      const Eigen::Vector3d& p = positions[mine[k]];
      const double d2 =
          sensor == nullptr
              ? (p - cell.sum).squaredNorm()
              : ((p - *sensor).normalized() - centroid_bearings[cell_of_mine[k]]).squaredNorm();
      if (d2 < cell.nearest_d2) {  // ties keep the lowest index
        cell.nearest_d2 = d2;
        cell.nearest = mine[k];
      }
    }
  }

  std::vector<Cell> cells;
};

}  // namespace

PointCloud voxelFilter(const PointCloud& cloud, double voxel_size_m,
                       VoxelRepresentative representative, const Eigen::Vector3d& sensor) {
  if (!(voxel_size_m > 0.0))
    throw std::invalid_argument("voxelFilter: voxel_size_m must be positive");
  if (cloud.size() > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("voxelFilter: more than 2^32 points");
  const double inverse_size = 1.0 / voxel_size_m;

  // Points are gathered into cells through hash maps (one per partition, in parallel) and only
  // the cells are sorted by key: a scan has 5-10 times more points than occupied voxels, and
  // sorting the points was the cost.
  const std::vector<Eigen::Vector3d>& positions = cloud.positions;
  std::vector<std::uint64_t> keys(positions.size());
  std::vector<std::uint8_t> parts(positions.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 8192),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const bool finite = positions[i].allFinite();
                        keys[i] = finite ? voxelKey(positions[i], inverse_size) : kNoKey;
                        parts[i] = finite ? Partition::of(keys[i]) : Partition::kCount;
                      }
                    });
  std::array<Partition, Partition::kCount> partitions;
  tbb::parallel_for(0u, Partition::kCount, [&](unsigned part) {
    partitions[part].gather(positions, keys, parts, part,
                            representative == VoxelRepresentative::bearing ? &sensor : nullptr);
  });

  // Keys are distinct, so the order is the same whatever is sorted: (key, cell) pairs.
  std::vector<std::pair<std::uint64_t, const Partition::Cell*>> order;
  for (const Partition& partition : partitions)
    for (const Partition::Cell& cell : partition.cells) order.emplace_back(cell.key, &cell);
  radixSortByVoxelKey(order);

  std::vector<Eigen::Vector3d> centroids;
  std::vector<std::size_t> representatives;
  centroids.reserve(order.size());
  representatives.reserve(order.size());
  for (const auto& [key, cell] : order) {
    centroids.push_back(cell->sum);
    representatives.push_back(cell->nearest);
  }
  PointCloud filtered = cloud.select(representatives);  // positions: the nearest returns
  if (representative == VoxelRepresentative::centroid) filtered.positions = std::move(centroids);
  return filtered;
}

VoxelRepresentative voxelRepresentative(std::string_view name) {
  if (name == "centroid") return VoxelRepresentative::centroid;
  if (name == "measured") return VoxelRepresentative::measured;
  if (name == "bearing") return VoxelRepresentative::bearing;
  throw std::invalid_argument("voxel representative must be centroid, measured or bearing, not '" +
                              std::string(name) + "'");
}

}  // namespace taiga::preprocess
