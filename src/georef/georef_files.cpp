// Reading the GNSS input of `taiga georef` and writing its outputs (formats in
// docs/georeferencing.md). Numbers are written with fmt's shortest round-trip representation, so
// grid coordinates keep full double precision.
#include "taiga/georef/georef_files.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <cctype>
#include <cmath>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/recording.hpp"

namespace taiga::georef {
namespace {

std::string lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string matrixRows(const Eigen::Matrix4d& M, const char* indent) {
  std::string text;
  for (int r = 0; r < 4; ++r)
    text += fmt::format("{}- [{}, {}, {}, {}]\n", indent, M(r, 0), M(r, 1), M(r, 2), M(r, 3));
  return text;
}

/// A JSON string literal (names of CRSs and files are plain, but quotes must not break it).
std::string jsonString(const std::string& text) {
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

GnssInput readGnssInput(const std::filesystem::path& path, const SystemConfig& config) {
  GnssInput input;
  if (lowercase(path.extension().string()) == ".csv") {
    input.fixes = readFixesCsv(path);
    return input;
  }
  input.from_recording = true;
  io::Recording recording = io::openRecording(path, config.recording, config.rig);
  while (auto event = recording.next()) {
    if (const auto* fix = std::get_if<GnssFix>(&*event)) {
      input.fixes.push_back(*fix);
    } else if (const auto* imu = std::get_if<ImuSample>(&*event)) {
      if (imu->orientation) input.imu_with_orientation.push_back(*imu);
    }
  }
  return input;
}

void writeGridCsv(const std::filesystem::path& path, const std::vector<GridPose>& poses) {
  auto out = fmt::output_file(path.string());
  out.print("t_s,easting_m,northing_m,height_m,yaw_grid_deg\n");
  for (const GridPose& pose : poses)
    out.print("{},{},{},{},{}\n", pose.t_s, pose.easting_m, pose.northing_m, pose.height_m,
              pose.yaw_grid_deg);
}

void writeGeoJson(const std::filesystem::path& path, const std::vector<GridPose>& poses, int epsg,
                  const std::string& name) {
  // GeoJSON (RFC 7946) drops the "crs" member and means WGS84 longitude/latitude, but QGIS and
  // GDAL still read the 2008 form's named CRS, which keeps the grid coordinates exact.
  auto out = fmt::output_file(path.string());
  out.print("{{\n  \"type\": \"FeatureCollection\",\n  \"name\": {},\n", jsonString(name));
  out.print("  \"crs\": {{\"type\": \"name\", \"properties\": {{\"name\": "
            "\"urn:ogc:def:crs:EPSG::{}\"}}}},\n",
            epsg);
  out.print("  \"features\": [{{\n    \"type\": \"Feature\",\n");
  out.print("    \"properties\": {{\"name\": {}, \"t_start_s\": {}, \"t_end_s\": {}}},\n",
            jsonString(name), poses.empty() ? 0.0 : poses.front().t_s,
            poses.empty() ? 0.0 : poses.back().t_s);
  out.print("    \"geometry\": {{\"type\": \"LineString\", \"coordinates\": [");
  for (std::size_t i = 0; i < poses.size(); ++i)
    out.print("{}\n      [{}, {}, {}]", i == 0 ? "" : ",", poses[i].easting_m, poses[i].northing_m,
              poses[i].height_m);
  out.print("\n    ]}}\n  }}]\n}}\n");
}

void writeGeorefYaml(const std::filesystem::path& path, const GeorefReport& report) {
  const GeorefFit& fit = report.fit;
  const Eigen::Vector3d rpy_deg = rollPitchYaw(fit.T_enu_world.rotation()) * kDegPerRad;
  auto out = fmt::output_file(path.string());
  out.print("# taiga georef: where the trajectory's world frame lies (docs/georeferencing.md)\n");
  out.print("method: {}\ntrajectory: {}\ngnss: {}\n", report.method, jsonString(report.trajectory_file),
            jsonString(report.gnss_file));
  out.print("epsg: {}\ncrs_name: {}\n", report.epsg, jsonString(report.crs_name));
  out.print("enu_origin:  # the local east-north-up frame of the fit\n");
  out.print("  latitude_deg: {}\n  longitude_deg: {}\n  height_ellipsoid_m: {}\n",
            report.origin.latitude_deg, report.origin.longitude_deg, report.origin.height_m);
  out.print("  easting_m: {}\n  northing_m: {}\n", report.origin_grid.x(), report.origin_grid.y());
  out.print("# p_enu = T_enu_world * p_world (rigid)\nT_enu_world:\n{}",
            matrixRows(fit.T_enu_world.matrix(), "  "));
  out.print("T_enu_world_translation_m: [{}, {}, {}]\n", fit.T_enu_world.translation().x(),
            fit.T_enu_world.translation().y(), fit.T_enu_world.translation().z());
  out.print("T_enu_world_roll_pitch_yaw_deg: [{}, {}, {}]\n", rpy_deg.x(), rpy_deg.y(), rpy_deg.z());
  out.print("# [E, N, h, 1] = T_epsg_world * [x, y, z, 1]: tangent plane at the ENU origin (scale and\n"
            "# meridian convergence there, heights unscaled); trajectory_epsg{}.csv is exact\n",
            report.epsg);
  out.print("T_epsg_world:\n{}", matrixRows(report.T_epsg_world, "  "));
  out.print("yaw_grid_world_deg: {}\n",
            std::atan2(report.T_epsg_world(1, 0), report.T_epsg_world(0, 0)) * kDegPerRad);
  out.print("# 1-sigma of T_enu_world: translation in ENU (m), small rotations about east (roll),\n"
            "# north (pitch) and up (yaw) (deg); from the normal equations scaled by the residuals\n");
  out.print("sigma:\n  east_m: {}\n  north_m: {}\n  up_m: {}\n", fit.sigma[0], fit.sigma[1], fit.sigma[2]);
  out.print("  roll_deg: {}\n  pitch_deg: {}\n  yaw_deg: {}\n", fit.sigma[3] * kDegPerRad,
            fit.sigma[4] * kDegPerRad, fit.sigma[5] * kDegPerRad);
  out.print("fixes:\n  total: {}\n  gated_no_fix: {}\n  gated_sigma: {}\n  gated_invalid: {}\n",
            report.fixes_total, report.gated_no_fix, report.gated_sigma, report.gated_invalid);
  out.print("  outside_trajectory: {}\n  in_trajectory_gap: {}\n  associated: {}\n",
            report.outside_span, report.in_gap, report.associated);
  out.print("  used: {}\n  outliers: {}\n  without_orientation: {}\n", fit.inliers, fit.outliers,
            fit.without_orientation);
  out.print("residual_rms_m:\n  total: {}\n  horizontal: {}\n  vertical: {}\n", fit.residual_rms_m,
            fit.horizontal_rms_m, fit.vertical_rms_m);
  out.print("iterations: {}\nconverged: {}\n", fit.iterations, fit.converged);
}

}  // namespace taiga::georef
