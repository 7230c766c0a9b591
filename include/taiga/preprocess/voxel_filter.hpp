#pragma once
// Voxel-grid downsampling: one point per occupied cubic voxel, at the centroid of the voxel's
// points. The registration source is the deskewed scan filtered at 0.4 m (thesis 3.1.1).
//
// The output is ordered by voxel key and does not depend on the input order within a voxel or
// on threads, so runs are repeatable.

#include <string_view>

#include "taiga/core/point_cloud.hpp"

namespace taiga::preprocess {

/// Which point stands for a voxel's points.
enum class VoxelRepresentative {
  centroid,  ///< their mean: least noisy, but inside a curved surface (a stem's arc, a hummock)
  measured,  ///< the return nearest to that mean: on the surface (docs/registration.md, "Bias")
};

/// One point per voxel of edge `voxel_size_m` (> 0), the centroid or the measured return nearest
/// to it; the other channels (time, intensity, ring, column) are taken from that nearest return.
/// Points with non-finite coordinates are dropped.
PointCloud voxelFilter(const PointCloud& cloud, double voxel_size_m,
                       VoxelRepresentative representative = VoxelRepresentative::centroid);

/// "centroid" or "measured" (OdometryConfig::voxel_point); throws std::invalid_argument else.
VoxelRepresentative voxelRepresentative(std::string_view name);

}  // namespace taiga::preprocess
