#pragma once
// Integer voxel coordinates and a small open-addressing hash table from voxel to cell index,
// shared by the NDT target and the incremental voxel statistics.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

#include "taiga/core/hash.hpp"

namespace taiga::registration {

/// A voxel (ix, iy, iz) packed into 63 bits, 21 per axis; valid for |i| < 2^20, i.e. up to
/// +-1048 km from the origin at 1 m cells. kInvalidVoxel marks a point outside that range.
using VoxelKey = std::int64_t;
inline constexpr VoxelKey kInvalidVoxel = -1;
inline constexpr std::int64_t kVoxelAxisLimit = std::int64_t{1} << 20;

inline VoxelKey packVoxel(std::int64_t ix, std::int64_t iy, std::int64_t iz) {
  if (ix <= -kVoxelAxisLimit || ix >= kVoxelAxisLimit || iy <= -kVoxelAxisLimit ||
      iy >= kVoxelAxisLimit || iz <= -kVoxelAxisLimit || iz >= kVoxelAxisLimit) {
    return kInvalidVoxel;
  }
  return ((ix + kVoxelAxisLimit) << 42) | ((iy + kVoxelAxisLimit) << 21) | (iz + kVoxelAxisLimit);
}

/// What one step along x, y or z adds to a key (x in bits 42.., y in 21.., z in 0..). Keys from
/// voxelOf are away from the axis limits (|i| < 1e6 < 2^20 - 1), so a step stays in its axis.
inline constexpr VoxelKey kVoxelStepX = VoxelKey{1} << 42;
inline constexpr VoxelKey kVoxelStepY = VoxelKey{1} << 21;
inline constexpr VoxelKey kVoxelStepZ = 1;

inline Eigen::Matrix<std::int64_t, 3, 1> unpackVoxel(VoxelKey key) {
  const std::int64_t mask = (std::int64_t{1} << 21) - 1;
  return {((key >> 42) & mask) - kVoxelAxisLimit, ((key >> 21) & mask) - kVoxelAxisLimit,
          (key & mask) - kVoxelAxisLimit};
}

/// Voxel of `p` for cells of `inverse_resolution` = 1 / cell size (1/m); NaN gives kInvalidVoxel.
inline VoxelKey voxelOf(const Eigen::Vector3d& p, double inverse_resolution) {
  const Eigen::Vector3d s = p * inverse_resolution;
  if (!(std::abs(s.x()) < 1e6 && std::abs(s.y()) < 1e6 && std::abs(s.z()) < 1e6)) {
    return kInvalidVoxel;
  }
  return packVoxel(static_cast<std::int64_t>(std::floor(s.x())),
                   static_cast<std::int64_t>(std::floor(s.y())),
                   static_cast<std::int64_t>(std::floor(s.z())));
}

/// Open addressing with linear probing, built once, read concurrently.
class VoxelIndex {
 public:
  VoxelIndex() = default;
  /// keys[i] -> i; keys must be distinct and valid.
  explicit VoxelIndex(const std::vector<VoxelKey>& keys);
  /// Index of `key`, or -1.
  std::int32_t find(VoxelKey key) const {
    if (keys_.empty() || key == kInvalidVoxel) return -1;
    std::uint64_t slot = hash(key) & mask_;
    while (true) {
      const VoxelKey k = keys_[slot];
      if (k == key) return values_[slot];
      if (k == kInvalidVoxel) return -1;
      slot = (slot + 1) & mask_;
    }
  }

 private:
  static std::uint64_t hash(VoxelKey key) { return MixedKeyHash{}(static_cast<std::uint64_t>(key)); }
  std::vector<VoxelKey> keys_;
  std::vector<std::int32_t> values_;
  std::uint64_t mask_ = 0;
};

}  // namespace taiga::registration
