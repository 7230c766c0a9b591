#pragma once
// File input and output of `taiga georef` (docs/georeferencing.md has the formats). The fitting
// code (fit.hpp) does no I/O; these functions do only I/O and formatting.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/georef/fit.hpp"
#include "taiga/georef/fix_preparation.hpp"
#include "taiga/georef/grid_output.hpp"

namespace taiga::georef {

/// Fixes CSV: a header line naming the columns, then one fix per line. Required columns t_s,
/// latitude_deg, longitude_deg, height_m (ellipsoidal); optional sigma_east_m, sigma_north_m,
/// sigma_up_m (1-sigma, all three or none) and status (-1 no fix, 0 fix, 1 SBAS, 2 GBAS; 0 when
/// absent). Lines starting with '#' and blank lines are ignored. InputError "FILE:LINE: ..."
/// naming the column on malformed input.
std::vector<GnssFix> readFixesCsv(const std::filesystem::path& path);

/// What a recording holds for georeferencing.
struct GnssInput {
  std::vector<GnssFix> fixes;
  std::vector<ImuSample> imu_with_orientation;  ///< IMU samples that carry an orientation
  bool from_recording = false;
};

/// A CSV file (by the .csv extension) or a recording (openRecording with `config`).
GnssInput readGnssInput(const std::filesystem::path& path, const SystemConfig& config);

/// Everything georef.yaml reports.
struct GeorefReport {
  std::string method;
  int epsg = 3067;
  std::string crs_name;
  std::string trajectory_file, gnss_file;
  geo::Geodetic origin;
  Eigen::Vector3d origin_grid = Eigen::Vector3d::Zero();  ///< E, N, h of the ENU origin
  GeorefFit fit;
  Eigen::Matrix4d T_epsg_world = Eigen::Matrix4d::Identity();
  std::size_t fixes_total = 0, gated_no_fix = 0, gated_sigma = 0, gated_invalid = 0;
  std::size_t outside_span = 0, in_gap = 0, associated = 0;
};

void writeGridCsv(const std::filesystem::path& path, const std::vector<GridPose>& poses);
void writeGeoJson(const std::filesystem::path& path, const std::vector<GridPose>& poses, int epsg,
                  const std::string& name);
void writeGeorefYaml(const std::filesystem::path& path, const GeorefReport& report);
/// fixes.csv: per fitted fix its time, position and reported 1-sigma in the fit's ENU frame, the
/// antenna in the world frame, the residual T_enu_world * p_world - p_enu and whether the fit
/// used it (0: an outlier or not used by the method).
void writeFixesCsv(const std::filesystem::path& path, const std::vector<AssociatedFix>& fixes,
                   const GeorefFit& fit);

/// The grid a georef.yaml places the world (map) frame in: its EPSG code and T_epsg_world, and
/// the fit's 1-sigma when the file has them.
struct GeorefGrid {
  int epsg = 0;
  Eigen::Matrix4d T_epsg_world = Eigen::Matrix4d::Identity();
  std::optional<double> sigma_horizontal_m;  ///< hypot of sigma.east_m and sigma.north_m
  std::optional<double> sigma_yaw_deg;
};
/// Reads `epsg`, `T_epsg_world` and `sigma` of a georef.yaml; InputError naming the file and the
/// key.
GeorefGrid readGeorefGrid(const std::filesystem::path& path);

}  // namespace taiga::georef
