#pragma once
// Voxel-grid downsampling: one point per occupied cubic voxel, at the centroid of the voxel's
// points. The registration source is the deskewed scan filtered at 0.4 m (thesis 3.1.1).
//
// The output is ordered by voxel key and does not depend on the input order within a voxel or
// on threads, so runs are repeatable.

#include "taiga/core/point_cloud.hpp"

namespace taiga::preprocess {

/// Centroid per voxel of edge `voxel_size_m` (> 0); the other channels (time, intensity, ring,
/// column) are taken from the voxel's point nearest to the centroid. Points with non-finite
/// coordinates are dropped.
PointCloud voxelFilter(const PointCloud& cloud, double voxel_size_m);

}  // namespace taiga::preprocess
