#include "taiga/preprocess/voxel_filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

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

PointCloud voxelFilter(const PointCloud& cloud, double voxel_size_m) {
  if (!(voxel_size_m > 0.0))
    throw std::invalid_argument("voxelFilter: voxel_size_m must be positive");
  const double inverse_size = 1.0 / voxel_size_m;
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed;
  keyed.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.positions[i].allFinite())
      keyed.emplace_back(voxelKey(cloud.positions[i], inverse_size), i);
  }
  std::sort(keyed.begin(), keyed.end());

  std::vector<Eigen::Vector3d> centroids;
  std::vector<std::size_t> representatives;
  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (end < keyed.size() && keyed[end].first == keyed[begin].first)
      sum += cloud.positions[keyed[end++].second];
    const Eigen::Vector3d centroid = sum / static_cast<double>(end - begin);
    std::size_t nearest = keyed[begin].second;
    double nearest_d2 = std::numeric_limits<double>::infinity();
    for (std::size_t k = begin; k < end; ++k) {
      const double d2 = (cloud.positions[keyed[k].second] - centroid).squaredNorm();
      if (d2 < nearest_d2) {
        nearest_d2 = d2;
        nearest = keyed[k].second;
      }
    }
    centroids.push_back(centroid);
    representatives.push_back(nearest);
    begin = end;
  }
  PointCloud filtered = cloud.select(representatives);
  filtered.positions = std::move(centroids);
  return filtered;
}

}  // namespace taiga::preprocess
