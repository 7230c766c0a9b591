#pragma once
// A dense, noise-free reference cloud of a simulated plot as a terrestrial laser scanner (TLS)
// would record it: static stations along the true trajectory, each scanning 360 deg in azimuth
// and 300 deg in the vertical (elevation -60 .. +90 deg on both sides of the zenith: everything
// but a 60 deg cone below the tripod), with a uniform angular step (fewer azimuth samples
// towards the zenith, step / cos(elevation)), exact ranges (no noise, no beam divergence, no
// dropouts), thinned on a voxel grid. For reference-trajectory and map-quality evaluation
// (`taiga simulate --reference-cloud`, docs/simulator.md).

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "taiga/core/point_cloud.hpp"
#include "taiga/sim/scene.hpp"

namespace taiga::sim {

class Simulation;

struct ReferenceCloudParams {
  double station_spacing_m = 15.0;  ///< path length between stations along the true trajectory
  double station_height_m = 1.5;    ///< scanner centre above the ground
  /// Angular step (azimuth at the horizon and elevation), deg: 0.06 deg is 1 cm at 10 m.
  double angular_step_deg = 0.06;
  double max_range_m = 40.0;      ///< farther hits are not recorded
  double min_elevation_deg = -60.0;
  double voxel_m = 0.02;  ///< one point per voxel (the nearest to its centre); 0 keeps all
};

/// Scanner positions: the true body position's ground point every station_spacing_m of walked
/// path (the first at the start), raised to station_height_m above the terrain. The walked path
/// is kept free of stems, so no station stands inside a tree.
std::vector<Eigen::Vector3d> referenceStations(const Simulation& simulation,
                                               const ReferenceCloudParams& params);

/// The thinned cloud of all stations, in the world frame: intensities are reflectivity x
/// cos(incidence) in percent (as the lidar's), rings the station index, times zero.
/// Deterministic and independent of the thread count. InputError for invalid params.
PointCloud simulateReferenceCloud(const Scene& scene, const std::vector<Eigen::Vector3d>& stations,
                                  const ReferenceCloudParams& params);

struct ReferenceCloudSummary {
  std::size_t stations = 0;
  std::size_t rays = 0;
  std::size_t points = 0;  ///< after thinning
  std::uintmax_t file_bytes = 0;
};

/// simulateReferenceCloud at referenceStations, written as LAS 1.4 (world frame, 1 mm
/// resolution, station index in the user data) to `path`.
ReferenceCloudSummary writeReferenceCloud(const Simulation& simulation,
                                          const std::filesystem::path& path,
                                          const ReferenceCloudParams& params);

}  // namespace taiga::sim
