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
  /// The return whose direction from the sensor is nearest the mean's: on the surface, and
  /// chosen without regard to its range, so its range noise is not selected for. (`measured`
  /// prefers returns whose noise put them behind the surface, toward the mean inside a convex
  /// one.)
  bearing,
};

/// One point per voxel of edge `voxel_size_m` (> 0), the centroid or a measured return near it;
/// the other channels (time, intensity, ring, column) are taken from the return nearest the
/// centroid (`bearing`: from the return it picks). `sensor` is the sensor's position in the
/// cloud's frame (for `bearing`). Points with non-finite coordinates are dropped.
PointCloud voxelFilter(const PointCloud& cloud, double voxel_size_m,
                       VoxelRepresentative representative = VoxelRepresentative::centroid,
                       const Eigen::Vector3d& sensor = Eigen::Vector3d::Zero());

/// "centroid", "measured" or "bearing" (OdometryConfig::voxel_point, local_map_point); throws
/// std::invalid_argument else.
VoxelRepresentative voxelRepresentative(std::string_view name);

}  // namespace taiga::preprocess
