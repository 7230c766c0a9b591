// Reading the GNSS input of `taiga georef` and writing its outputs (formats in
// docs/georeferencing.md). georef.yaml is emitted with yaml-cpp and trajectory.geojson with
// nlohmann-json, which quote and escape the file and CRS names; numbers keep full double precision
// (grid coordinates need it): in the YAML as fmt's shortest round-trip text, in the GeoJSON as
// nlohmann-json's round-trip text.
#include "taiga/georef/georef_files.hpp"

#include <fmt/format.h>
#include <fmt/os.h>
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/recording.hpp"

namespace taiga::georef {
namespace {

std::string lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

/// A double for the YAML emitter: yaml-cpp would write 17 significant digits (0.1 as
/// 0.10000000000000001), so finite values go out as fmt's shortest text that reads back as the
/// same double, a plain scalar; non-finite ones as yaml-cpp's .nan, .inf and -.inf, which YAML
/// readers (yaml-cpp's as<double> too) take for numbers.
struct Exact {
  double value;
};

YAML::Emitter& operator<<(YAML::Emitter& out, Exact number) {
  if (std::isfinite(number.value)) return out << fmt::format("{}", number.value);
  return out << number.value;
}

/// The rows of M as a block sequence of flow sequences ("- [a, b, c, d]"), one row per line.
void emitMatrixRows(YAML::Emitter& out, const Eigen::Matrix4d& M) {
  out << YAML::BeginSeq;
  for (int r = 0; r < 4; ++r)
    out << YAML::Flow << YAML::BeginSeq << Exact{M(r, 0)} << Exact{M(r, 1)} << Exact{M(r, 2)}
        << Exact{M(r, 3)} << YAML::EndSeq;
  out << YAML::EndSeq;
}

void emitVector(YAML::Emitter& out, const Eigen::Vector3d& v) {
  out << YAML::Flow << YAML::BeginSeq << Exact{v.x()} << Exact{v.y()} << Exact{v.z()}
      << YAML::EndSeq;
}

/// A comment on lines of its own before the next top-level key (yaml-cpp would otherwise append it
/// to the line of the previous value). Lines of `text` are separated by '\n'.
void emitCommentLines(YAML::Emitter& out, const std::string& text) {
  out << YAML::Newline << YAML::Comment(text);
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

void writeFixesCsv(const std::filesystem::path& path, const std::vector<AssociatedFix>& fixes,
                   const GeorefFit& fit) {
  auto out = fmt::output_file(path.string());
  out.print(
      "t_s,east_m,north_m,up_m,sigma_east_m,sigma_north_m,sigma_up_m,x_world_m,y_world_m,"
      "z_world_m,residual_east_m,residual_north_m,residual_up_m,used\n");
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const AssociatedFix& pair = fixes[i];
    const Eigen::Vector3d sigma = pair.fix.covariance_enu_m2.diagonal().cwiseSqrt();
    const Eigen::Vector3d residual = fit.T_enu_world * pair.p_world - pair.fix.p_enu;
    const bool used = i < fit.inlier.size() && fit.inlier[i];
    out.print("{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", pair.fix.t_s, pair.fix.p_enu.x(),
              pair.fix.p_enu.y(), pair.fix.p_enu.z(), sigma.x(), sigma.y(), sigma.z(),
              pair.p_world.x(), pair.p_world.y(), pair.p_world.z(), residual.x(), residual.y(),
              residual.z(), used ? 1 : 0);
  }
}

void writeGeoJson(const std::filesystem::path& path, const std::vector<GridPose>& poses, int epsg,
                  const std::string& name) {
  // GeoJSON (RFC 7946) drops the "crs" member and means WGS84 longitude/latitude, but QGIS and
  // GDAL still read the 2008 form's named CRS, which keeps the grid coordinates exact.
  nlohmann::ordered_json coordinates = nlohmann::ordered_json::array();
  for (const GridPose& pose : poses)
    coordinates.push_back({pose.easting_m, pose.northing_m, pose.height_m});
  nlohmann::ordered_json feature;
  feature["type"] = "Feature";
  feature["properties"] = {{"name", name},
                           {"t_start_s", poses.empty() ? 0.0 : poses.front().t_s},
                           {"t_end_s", poses.empty() ? 0.0 : poses.back().t_s}};
  feature["geometry"] = {{"type", "LineString"}, {"coordinates", std::move(coordinates)}};
  nlohmann::ordered_json geojson;
  geojson["type"] = "FeatureCollection";
  geojson["name"] = name;
  geojson["crs"] = {{"type", "name"},
                    {"properties", {{"name", fmt::format("urn:ogc:def:crs:EPSG::{}", epsg)}}}};
  geojson["features"].push_back(std::move(feature));
  // A file name that is not UTF-8 gets U+FFFD in the output instead of an exception.
  fmt::output_file(path.string())
      .print("{}\n", geojson.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace));
}

void writeGeorefYaml(const std::filesystem::path& path, const GeorefReport& report) {
  const GeorefFit& fit = report.fit;
  const Eigen::Vector3d rpy_deg = rollPitchYaw(fit.T_enu_world.rotation()) * kDegPerRad;
  YAML::Emitter out;
  out << YAML::Comment(
      "taiga georef: where the trajectory's world frame lies (docs/georeferencing.md)");
  out << YAML::BeginMap;
  out << YAML::Key << "method" << YAML::Value << report.method;
  out << YAML::Key << "trajectory" << YAML::Value << YAML::DoubleQuoted << report.trajectory_file;
  out << YAML::Key << "gnss" << YAML::Value << YAML::DoubleQuoted << report.gnss_file;
  out << YAML::Key << "epsg" << YAML::Value << report.epsg;
  out << YAML::Key << "crs_name" << YAML::Value << YAML::DoubleQuoted << report.crs_name;
  out << YAML::Key << "enu_origin" << YAML::Comment("the local east-north-up frame of the fit")
      << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "latitude_deg" << YAML::Value << Exact{report.origin.latitude_deg};
  out << YAML::Key << "longitude_deg" << YAML::Value << Exact{report.origin.longitude_deg};
  out << YAML::Key << "height_ellipsoid_m" << YAML::Value << Exact{report.origin.height_m};
  out << YAML::Key << "easting_m" << YAML::Value << Exact{report.origin_grid.x()};
  out << YAML::Key << "northing_m" << YAML::Value << Exact{report.origin_grid.y()};
  out << YAML::EndMap;

  emitCommentLines(out, "p_enu = T_enu_world * p_world (rigid)");
  out << YAML::Key << "T_enu_world" << YAML::Value;
  emitMatrixRows(out, fit.T_enu_world.matrix());
  out << YAML::Key << "T_enu_world_translation_m" << YAML::Value;
  emitVector(out, fit.T_enu_world.translation());
  out << YAML::Key << "T_enu_world_roll_pitch_yaw_deg" << YAML::Value;
  emitVector(out, rpy_deg);

  emitCommentLines(
      out, fmt::format("[E, N, h, 1] = T_epsg_world * [x, y, z, 1]: tangent plane at the ENU "
                       "origin (scale and\nmeridian convergence there, heights unscaled); "
                       "trajectory_epsg{}.csv is exact",
                       report.epsg));
  out << YAML::Key << "T_epsg_world" << YAML::Value;
  emitMatrixRows(out, report.T_epsg_world);
  // The heading of the grid's x axis in the world, from the tangent-plane matrix (which carries
  // the grid scale, so it is no rotation for lie::SO3::yaw()).
  out << YAML::Key << "yaw_grid_world_deg" << YAML::Value
      << Exact{std::atan2(report.T_epsg_world(1, 0), report.T_epsg_world(0, 0)) * kDegPerRad};

  emitCommentLines(out,
                   "1-sigma of T_enu_world: translation in ENU (m), small rotations about east "
                   "(roll),\nnorth (pitch) and up (yaw) (deg); from the normal equations scaled by "
                   "the residuals");
  out << YAML::Key << "sigma" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "east_m" << YAML::Value << Exact{fit.sigma[0]};
  out << YAML::Key << "north_m" << YAML::Value << Exact{fit.sigma[1]};
  out << YAML::Key << "up_m" << YAML::Value << Exact{fit.sigma[2]};
  out << YAML::Key << "roll_deg" << YAML::Value << Exact{fit.sigma[3] * kDegPerRad};
  out << YAML::Key << "pitch_deg" << YAML::Value << Exact{fit.sigma[4] * kDegPerRad};
  out << YAML::Key << "yaw_deg" << YAML::Value << Exact{fit.sigma[5] * kDegPerRad};
  out << YAML::EndMap;

  out << YAML::Key << "fixes" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "total" << YAML::Value << report.fixes_total;
  out << YAML::Key << "gated_no_fix" << YAML::Value << report.gated_no_fix;
  out << YAML::Key << "gated_sigma" << YAML::Value << report.gated_sigma;
  out << YAML::Key << "gated_invalid" << YAML::Value << report.gated_invalid;
  out << YAML::Key << "outside_trajectory" << YAML::Value << report.outside_span;
  out << YAML::Key << "in_trajectory_gap" << YAML::Value << report.in_gap;
  out << YAML::Key << "associated" << YAML::Value << report.associated;
  out << YAML::Key << "used" << YAML::Value << fit.inliers;
  out << YAML::Key << "outliers" << YAML::Value << fit.outliers;
  out << YAML::Key << "without_orientation" << YAML::Value << fit.without_orientation;
  out << YAML::EndMap;

  out << YAML::Key << "residual_rms_m" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "total" << YAML::Value << Exact{fit.residual_rms_m};
  out << YAML::Key << "horizontal" << YAML::Value << Exact{fit.horizontal_rms_m};
  out << YAML::Key << "vertical" << YAML::Value << Exact{fit.vertical_rms_m};
  out << YAML::EndMap;
  if (fit.error_model) {
    const GnssErrorModel& model = *fit.error_model;
    emitCommentLines(out,
                     "robust: the fixes' errors as the fit modelled them (reported sigma times a "
                     "Gauss-Markov\nprocess); sigma above is the error this model expects for "
                     "these fixes (docs/georeferencing.md)");
    out << YAML::Key << "error_model" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "configured_correlation_time_s" << YAML::Value
        << Exact{model.configured_correlation_time_s};
    out << YAML::Key << "correlation_time_s" << YAML::Comment("the most likely") << YAML::Value
        << Exact{model.correlation_time_s};
    out << YAML::Key << "white_share" << YAML::Comment("white / Gauss-Markov variance")
        << YAML::Value << Exact{model.white_share};
    out << YAML::Key << "sigma_trust"
        << YAML::Comment("share of the reported sigmas' swings believed") << YAML::Value
        << Exact{model.sigma_trust};
    out << YAML::Key << "sigma_mean_window_s" << YAML::Value << Exact{model.sigma_mean_window_s};
    out << YAML::Key << "sigma_scale_horizontal" << YAML::Comment("observed / reported")
        << YAML::Value << Exact{model.sigma_scale_horizontal};
    out << YAML::Key << "sigma_scale_up" << YAML::Value << Exact{model.sigma_scale_up};
    out << YAML::Key << "independent_fixes" << YAML::Value << Exact{model.independent_fixes};
    out << YAML::Key << "whitened_lag_one_correlation" << YAML::Comment("near 0 if tau is right")
        << YAML::Value << Exact{model.whitened_lag_one_correlation};
    out << YAML::EndMap;
  }
  out << YAML::Key << "iterations" << YAML::Value << fit.iterations;
  out << YAML::Key << "converged" << YAML::Value << fit.converged;
  out << YAML::EndMap;
  fmt::output_file(path.string()).print("{}\n", out.c_str());
}

GeorefGrid readGeorefGrid(const std::filesystem::path& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: {}", path.string(), e.what()));
  }
  GeorefGrid grid;
  try {
    grid.epsg = root["epsg"].as<int>();
    const YAML::Node rows = root["T_epsg_world"];
    if (!rows || !rows.IsSequence() || rows.size() != 4)
      throw InputError(fmt::format("{}: T_epsg_world: expected 4 rows", path.string()));
    for (std::size_t r = 0; r < 4; ++r) {
      if (!rows[r].IsSequence() || rows[r].size() != 4)
        throw InputError(
            fmt::format("{}: T_epsg_world row {}: expected 4 numbers", path.string(), r));
      for (std::size_t c = 0; c < 4; ++c) grid.T_epsg_world(r, c) = rows[r][c].as<double>();
    }
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: epsg and T_epsg_world expected (a georef.yaml of taiga): {}",
                                 path.string(), e.what()));
  }
  if (!grid.T_epsg_world.allFinite())
    throw InputError(fmt::format("{}: T_epsg_world has non-finite values", path.string()));
  // The 1-sigma is optional (georef.yaml files before it had one, or written by hand).
  try {
    if (const YAML::Node sigma = root["sigma"]; sigma && sigma.IsMap()) {
      const double east = sigma["east_m"].as<double>(), north = sigma["north_m"].as<double>(),
                   yaw = sigma["yaw_deg"].as<double>();
      if (std::isfinite(east) && std::isfinite(north) && std::isfinite(yaw)) {
        grid.sigma_horizontal_m = std::hypot(east, north);
        grid.sigma_yaw_deg = yaw;
      }
    }
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: sigma: expected east_m, north_m and yaw_deg: {}",
                                 path.string(), e.what()));
  }
  return grid;
}

}  // namespace taiga::georef
