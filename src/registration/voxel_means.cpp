#include "taiga/registration/voxel_means.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "taiga/core/radix_sort.hpp"
#include "voxel_quanta.hpp"

namespace taiga::registration {

VoxelMeans::VoxelMeans(double resolution_m)
    : resolution_m_(resolution_m), inverse_resolution_(1.0 / resolution_m) {
  if (!(resolution_m > 0.0) || !std::isfinite(resolution_m)) {
    throw std::invalid_argument("VoxelMeans: resolution_m must be positive, got " +
                                std::to_string(resolution_m));
  }
}

void VoxelMeans::update(const Eigen::Vector3d& p, int sign) {
  VoxelKey key;
  std::int64_t q[3];
  if (!detail::quantize(p, resolution_m_, inverse_resolution_, key, q)) {
    if (sign > 0) ++skipped_;
    return;
  }
  const auto it = sign > 0 ? cells_.try_emplace(key).first : cells_.find(key);
  if (it == cells_.end())
    throw std::logic_error("VoxelMeans::remove: a point that was never added");
  Sums& sums = it.value();
  sums.count += sign;
  for (int a = 0; a < 3; ++a) sums.s[a] += sign * q[a];
  if (sums.count == 0) cells_.erase(it);
}

void VoxelMeans::add(std::span<const Eigen::Vector3d> points) {
  for (const Eigen::Vector3d& p : points) update(p, +1);
}

void VoxelMeans::remove(std::span<const Eigen::Vector3d> points) {
  for (const Eigen::Vector3d& p : points) update(p, -1);
}

std::size_t VoxelMeans::numPoints() const {
  std::size_t n = 0;
  for (const auto& [key, sums] : cells_) n += static_cast<std::size_t>(sums.count);
  return n;
}

std::vector<Eigen::Vector3d> VoxelMeans::means() const {
  std::vector<std::pair<VoxelKey, Eigen::Vector3d>> cells;
  cells.reserve(cells_.size());
  for (const auto& [key, sums] : cells_)
    cells.emplace_back(key, detail::meanOf(key, resolution_m_, sums.count, sums.s));
  radixSortByVoxelKey(cells);
  std::vector<Eigen::Vector3d> out;
  out.reserve(cells.size());
  for (const auto& cell : cells) out.push_back(cell.second);
  return out;
}

std::vector<Eigen::Vector3d> VoxelMeans::meansInTableOrder() const {
  std::vector<Eigen::Vector3d> out;
  out.reserve(cells_.size());
  for (const auto& [key, sums] : cells_)
    out.push_back(detail::meanOf(key, resolution_m_, sums.count, sums.s));
  return out;
}

std::vector<Eigen::Vector3d> voxelDownsample(std::span<const Eigen::Vector3d> points,
                                             double leaf_m) {
  VoxelMeans means(leaf_m);
  means.add(points);
  return means.means();
}

}  // namespace taiga::registration
