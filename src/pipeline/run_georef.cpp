#include "run_georef.hpp"

#include <fmt/format.h>

#include <chrono>
#include <fstream>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/georef/georeference.hpp"
#include "taiga/mapping/map_export.hpp"

namespace taiga::pipeline {

GeorefRunReport georeferenceRun(const Trajectory& trajectory, const georef::GnssInput& gnss,
                                const SystemConfig& config, const std::string& recording_name,
                                const RunMap& map, const std::filesystem::path& out_dir) {
  GeorefRunReport report;
  report.fixes = gnss.fixes.size();
  report.method = config.georef.method;
  report.epsg = config.georef.epsg;
  georef::Georeference result;
  try {
    result = georef::georeference(trajectory, gnss, georef::settingsFrom(config.georef), config.rig,
                                  "trajectory.tum", recording_name);
  } catch (const InputError& e) {
    report.skipped = e.what();
    logger().warn("not georeferenced: {}", report.skipped);
    return report;
  }
  const std::filesystem::path dir = out_dir / "georef";
  georef::writeGeoreference(dir, result, "trajectory");
  const georef::GeorefFit& fit = result.report.fit;
  report.inliers = fit.inliers;
  report.outliers = fit.outliers;
  report.horizontal_rms_m = fit.horizontal_rms_m;
  report.vertical_rms_m = fit.vertical_rms_m;
  report.sigma = fit.sigma;

  // The map through the tangent-plane approximation at the ENU origin (scale and meridian
  // convergence included): 0.2 mm off at 50 m from the origin, 1.8 mm at 150 m (tests/geo).
  const auto export_start = std::chrono::steady_clock::now();
  mapping::MapExportOptions options;
  options.voxel_m = map.voxel_m;
  options.T_out_map = Eigen::Affine3d(result.report.T_epsg_world);
  options.wkt = geo::CoordinateConverter(report.epsg).wkt();
  mapping::exportMap(map.store, map.poses_T_map_body,
                     dir / fmt::format("map_epsg{}.las", report.epsg), options);
  report.map_export_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - export_start).count();
  logger().info(
      "georeferenced ({}): {} of {} fixes, residual RMS {:.2f} m horizontal, 1-sigma "
      "{:.2f} m east {:.2f} m north {:.2f} deg yaw; {}",
      report.method, report.inliers, report.fixes, report.horizontal_rms_m, report.sigma[0],
      report.sigma[1], report.sigma[5] * kDegPerRad, dir.string());
  return report;
}

GnssRecorder::GnssRecorder(const SystemConfig& config)
    : config_(config.georef), keep_imu_orientation_(config.georef.method == "pf6") {}

void GnssRecorder::onImu(const ImuSample& sample) {
  if (keep_imu_orientation_ && sample.orientation) gnss_.imu_with_orientation.push_back(sample);
}

void GnssRecorder::onGnssFix(const GnssFix& fix) {
  gnss_.fixes.push_back(fix);
  if (!online_) online_.emplace(georef::settingsFrom(config_));
  online_->addFix(fix);
}

// The online georeference follows the odometry's own poses (T_odom_body): the estimate absorbs
// the odometry's drift as the fixes come, which a correction by the graph would only disturb.
void GnssRecorder::onScan(const ScanOutcome& scan, const lie::SE3& /*T_map_odom*/) {
  if (!online_) return;
  online_->addPose(scan.t_s, scan.T_odom_body);
  if (auto grid = online_->toGrid(scan.t_s, scan.T_odom_body))
    online_poses_.push_back({*grid, online_->estimate()->fit.sigma, online_->estimate()->fixes});
}

void GnssRecorder::writeOnline(const std::filesystem::path& dir) const {
  if (online_poses_.empty()) return;
  std::filesystem::create_directories(dir);
  const std::filesystem::path path =
      dir / fmt::format("trajectory_online_epsg{}.csv", config_.epsg);
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("{}: cannot write", path.string()));
  out << "t_s,easting_m,northing_m,height_m,yaw_grid_deg,sigma_east_m,sigma_north_m,sigma_up_m,"
         "sigma_yaw_deg,fixes\n";
  for (const OnlineGridPose& p : online_poses_) {
    out << fmt::format("{:.6f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{}\n",
                       p.pose.t_s, p.pose.easting_m, p.pose.northing_m, p.pose.height_m,
                       p.pose.yaw_grid_deg, p.sigma[0], p.sigma[1], p.sigma[2],
                       p.sigma[5] * kDegPerRad, p.fixes);
  }
}

}  // namespace taiga::pipeline
