#include "truth_outputs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "taiga/core/angles.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/sim/georef_truth.hpp"
#include "taiga/sim/scenario_yaml.hpp"

namespace taiga::sim {

void detail::writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error(fmt::format("{}: cannot write", path.string()));
}

GeorefTruth georefTruth(const GnssParams& gnss) {
  const geo::CoordinateConverter converter(gnss.georef_epsg);
  const geo::Geodetic origin{gnss.origin_latitude_deg, gnss.origin_longitude_deg,
                             gnss.origin_height_m};
  const geo::GridTangent tangent = converter.gridTangent(origin);
  GeorefTruth truth;
  truth.epsg = gnss.georef_epsg;
  truth.crs_name = converter.crsName();
  truth.origin_latitude_deg = origin.latitude_deg;
  truth.origin_longitude_deg = origin.longitude_deg;
  truth.origin_height_m = origin.height_m;
  truth.origin_easting_m = tangent.T_grid_enu(0, 3);
  truth.origin_northing_m = tangent.T_grid_enu(1, 3);
  truth.world_yaw_from_east_deg = gnss.world_yaw_deg;
  truth.meridian_convergence_deg = tangent.yaw_deg;
  truth.yaw_grid_world_deg = tangent.yaw_deg + gnss.world_yaw_deg;
  truth.scale = tangent.scale;
  Eigen::Matrix4d T_enu_world = Eigen::Matrix4d::Identity();
  const double yaw = gnss.world_yaw_deg / kDegPerRad;
  T_enu_world.topLeftCorner<2, 2>() << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
  truth.T_epsg_world = tangent.T_grid_enu * T_enu_world;
  return truth;
}

namespace detail {

const char* speciesName(Species s) {
  switch (s) {
    case Species::kPine:
      return "pine";
    case Species::kSpruce:
      return "spruce";
    case Species::kBirch:
      return "birch";
    case Species::kSapling:
      return "sapling";
  }
  return "unknown";
}

void writeTreesCsv(const std::filesystem::path& path, const Scene& scene) {
  // Full precision ({} is the shortest text that reads back to the same double).
  // x_bh_m, y_bh_m: the axis at breast height, where DBH is measured (lean and bow included).
  std::string text =
      "id,x_m,y_m,z_m,dbh_m,height_m,lean_deg,lean_azimuth_deg,species,x_bh_m,y_bh_m\n";
  std::size_t id = 0;
  for (const Tree& t : scene.trees()) {
    const Eigen::Vector3d bh = t.axisAt(1.3);
    text +=
        fmt::format("{},{},{},{},{},{},{},{},{},{},{}\n", id++, t.base_world.x(), t.base_world.y(),
                    t.base_world.z(), t.dbh_m, t.height_m, t.lean_rad * kDegPerRad,
                    t.lean_azimuth_rad * kDegPerRad, speciesName(t.species), bh.x(), bh.y());
  }
  writeText(path, text);
}

void writeGeorefTruthYaml(const std::filesystem::path& path, const Simulation& simulation) {
  const GeorefTruth g = georefTruth(simulation.scenario().gnss);
  std::string matrix;
  for (int r = 0; r < 4; ++r) {
    matrix += fmt::format("  - [{}, {}, {}, {}]\n", g.T_epsg_world(r, 0), g.T_epsg_world(r, 1),
                          g.T_epsg_world(r, 2), g.T_epsg_world(r, 3));
  }
  writeText(
      path,
      fmt::format(
          "# Where the simulated world frame lies in EPSG:{} ({}).\n"
          "# Geodetic coordinates are WGS84 = ETRS89 here (no epoch, no plate motion); heights "
          "are\n"
          "# ellipsoidal. The world frame is the local east-north-up frame at the origin turned "
          "by\n"
          "# world_yaw_from_east_deg about up. The grid is turned against the local frame by the\n"
          "# meridian convergence and scaled by the projection's point scale (and R / (R + h)).\n"
          "epsg: {}\n"
          "crs_name: \"{}\"\n"
          "origin:\n"
          "  latitude_deg: {}\n"
          "  longitude_deg: {}\n"
          "  height_ellipsoid_m: {}\n"
          "  easting_m: {}\n"
          "  northing_m: {}\n"
          "world_yaw_from_east_deg: {}  # angle from local east to world x, counterclockwise\n"
          "meridian_convergence_deg: {}  # angle from grid easting to local east, "
          "counterclockwise\n"
          "yaw_grid_world_deg: {}  # angle from grid easting to world x, counterclockwise\n"
          "scale: {}  # grid metres per world metre at the origin\n"
          "# [E, N, h, 1] = T_epsg_world [x, y, z, 1], row by row: scale * Rz(yaw_grid_world_deg)\n"
          "# horizontally, heights unscaled. The tangent-plane approximation at the origin: off "
          "by\n"
          "# 0.2 mm at 50 m from it and 1.8 mm at 150 m (grid curvature, Earth curvature in h).\n"
          "# For exact coordinates convert world -> geodetic -> grid (taiga::geo).\n"
          "T_epsg_world:\n{}",
          g.epsg, g.crs_name, g.epsg, g.crs_name, g.origin_latitude_deg, g.origin_longitude_deg,
          g.origin_height_m, g.origin_easting_m, g.origin_northing_m, g.world_yaw_from_east_deg,
          g.meridian_convergence_deg, g.yaw_grid_world_deg, g.scale, matrix));
}

void writeScenarioYaml(const std::filesystem::path& path, const Simulation& simulation) {
  Scenario effective = simulation.scenario();
  effective.duration_s = simulation.duration_s();
  writeText(path, fmt::format("# The effective scenario of this recording. To simulate it again:\n"
                              "#   taiga simulate --overrides scenario.yaml --seed {} --out DIR\n",
                              simulation.seed()) +
                      scenarioYaml(effective));
}

}  // namespace detail
}  // namespace taiga::sim
