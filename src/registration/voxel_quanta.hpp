#pragma once
// The quantization VoxelStatistics and VoxelMeans share (voxel_statistics.hpp): a point's cell,
// its position about the cell's centre in quanta of VoxelStatistics::kQuantum_m, and a cell's
// mean from its integer sums. One definition, so that both give the same means bit for bit.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "taiga/registration/voxel_index.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration::detail {

/// p's cell and its position about the cell centre in quanta; false for a point without a cell
/// (non-finite, or beyond the keys' range).
inline bool quantize(const Eigen::Vector3d& p, double resolution_m, double inverse_resolution,
                     VoxelKey& key, std::int64_t q[3]) {
  key = voxelOf(p, inverse_resolution);
  if (key == kInvalidVoxel) return false;
  const Eigen::Matrix<std::int64_t, 3, 1> index = unpackVoxel(key);
  for (int a = 0; a < 3; ++a) {
    const double centre = (static_cast<double>(index[a]) + 0.5) * resolution_m;
    q[a] = std::llround((p[a] - centre) / VoxelStatistics::kQuantum_m);
  }
  return true;
}

/// The mean of a cell's `count` points whose quanta sum to s.
inline Eigen::Vector3d meanOf(VoxelKey key, double resolution_m, std::int64_t count,
                              const std::int64_t s[3]) {
  const Eigen::Matrix<std::int64_t, 3, 1> index = unpackVoxel(key);
  const Eigen::Vector3d centre = (index.cast<double>().array() + 0.5) * resolution_m;
  const Eigen::Vector3d sum(static_cast<double>(s[0]), static_cast<double>(s[1]),
                            static_cast<double>(s[2]));
  return centre + sum * (VoxelStatistics::kQuantum_m / static_cast<double>(count));
}

}  // namespace taiga::registration::detail
