// taiga georef --als: reads a run's map and trajectory, the ALS tiles that overlap them, and a
// starting pose (the run's GNSS georeference, or --guess); writes the map and trajectory in the
// grid with the registration's report.
#include "georef_als.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "command.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/georef/als_registration.hpp"
#include "taiga/georef/georef_files.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/io/las_writer.hpp"
#include "taiga/io/trajectory_io.hpp"

namespace taiga::app {
namespace {
namespace fs = std::filesystem;

struct Guess {
  lie::SE3 T_grid_map;
  int epsg = 3067;
  double search_m = 0.0, search_deg = 0.0;
  std::string source;
};

/// --guess "E,N,YAW_DEG" (a user's rough pose: 25 m / 25 deg searched) or the run's GNSS
/// georeference (8 m / 8 deg).
Guess startingPose(const AlsGeorefOptions& options) {
  Guess guess;
  if (!options.guess.empty()) {
    std::vector<double> values;
    std::stringstream text(options.guess);
    for (std::string field; std::getline(text, field, ',');) {
      try {
        values.push_back(std::stod(field));
      } catch (const std::exception&) {
        values.clear();
        break;
      }
    }
    if (values.size() != 3 || !std::isfinite(values[0]) || !std::isfinite(values[1]) ||
        !std::isfinite(values[2]))
      throw InputError(fmt::format("--guess: expected E,N,YAW_DEG, found '{}'", options.guess));
    // The height comes from the ALS (the registration's height step); the heading turns the
    // map's x axis from grid east, counterclockwise.
    guess.T_grid_map = lie::SE3(lie::SO3::Exp(Eigen::Vector3d(0.0, 0.0, values[2] * kRadPerDeg)),
                                Eigen::Vector3d(values[0], values[1], 0.0));
    guess.search_m = guess.search_deg = 25.0;
    guess.source = "--guess";
  } else {
    const fs::path yaml = fs::path(options.run) / "georef" / "georef.yaml";
    if (!fs::exists(yaml))
      throw InputError(fmt::format(
          "{}: no GNSS georeference to start from; give --guess E,N,YAW_DEG", yaml.string()));
    const georef::GeorefGrid grid = georef::readGeorefGrid(yaml);
    const Eigen::Matrix3d A = grid.T_epsg_world.topLeftCorner<3, 3>();
    Eigen::Matrix3d R = A;
    R.col(0).normalize();
    R.col(1).normalize();
    R.col(2).normalize();
    guess.T_grid_map = lie::SE3(lie::SO3(Eigen::Quaterniond(R).normalized()),
                                grid.T_epsg_world.topRightCorner<3, 1>());
    guess.epsg = grid.epsg;
    // Wide enough for the GNSS fit's uncertainty: 4 sigma, at least 3 m and 3 deg (the search's
    // own steps and a margin for a sigma that is a little optimistic), at most 25 (as without
    // GNSS); 8 m and 8 deg for a georef.yaml without a sigma.
    guess.search_m = grid.sigma_horizontal_m
                         ? std::clamp(4.0 * *grid.sigma_horizontal_m, 3.0, 25.0)
                         : 8.0;
    guess.search_deg =
        grid.sigma_yaw_deg ? std::clamp(4.0 * *grid.sigma_yaw_deg, 3.0, 25.0) : 8.0;
    guess.source = yaml.string();
  }
  if (options.epsg) guess.epsg = *options.epsg;
  if (options.search_m) guess.search_m = *options.search_m;
  if (options.search_deg) guess.search_deg = *options.search_deg;
  return guess;
}

std::vector<fs::path> lasFiles(const std::vector<std::string>& inputs) {
  std::vector<fs::path> files;
  for (const std::string& input : inputs) {
    if (fs::is_directory(input)) {
      for (const fs::directory_entry& e : fs::directory_iterator(input))
        if (io::lowercaseExtension(e.path()) == ".las") files.push_back(e.path());
    } else if (fs::exists(input)) {
      files.emplace_back(input);
    } else {
      throw InputError(fmt::format("{}: no such ALS file or directory", input));
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError("--als: no .las file given");
  return files;
}

/// The ALS points within `area` (grid, x-y), read from the tiles whose header bounds meet it.
std::vector<Eigen::Vector3d> readAls(const std::vector<fs::path>& files,
                                     const Eigen::AlignedBox2d& area,
                                     std::vector<std::string>& used) {
  std::vector<Eigen::Vector3d> points;
  for (const fs::path& file : files) {
    io::LasReader reader(file);
    const Eigen::AlignedBox2d tile(reader.header().min_m.head<2>(),
                                   reader.header().max_m.head<2>());
    if (!tile.intersects(area)) continue;
    used.push_back(file.string());
    for (std::uint64_t first = 0; first < reader.pointCount(); first += 1u << 20) {
      PointCloud chunk;
      reader.read(first, 1u << 20, chunk);
      for (const Eigen::Vector3d& p : chunk.positions)
        if (area.contains(p.head<2>())) points.push_back(p);
    }
  }
  return points;
}

void writeReport(const fs::path& path, const georef::AlsRegistration& r, const Guess& guess,
                 double scale, const std::vector<std::string>& tiles) {
  auto out = fmt::output_file(path.string());
  out.print(
      "# taiga georef --als: the run's map registered to airborne lidar "
      "(docs/georeferencing.md, ALS)\n");
  out.print("ok: {}\n", r.ok ? "true" : "false");
  if (!r.ok) out.print("reason: \"{}\"\n", r.reason);
  out.print("epsg: {}\nstart: \"{}\"\nsearch_m: {}\nsearch_deg: {}\n", guess.epsg, guess.source,
            guess.search_m, guess.search_deg);
  out.print("als_tiles:\n");
  for (const std::string& t : tiles) out.print("  - \"{}\"\n", t);
  out.print(
      "map_points: {}\nals_points: {}\ncoverage: {:.4f}\nscore: {:.4f}\nsecond_score: {:.4f}\n",
      r.map_points, r.als_points, r.coverage, r.score, r.second_score);
  out.print("height_shift_m: {:.4f}\ngrid_scale: {:.8f}\n", r.height_shift_m, scale);
  if (!r.ok) return;
  out.print(
      "# [E, N, h, 1] = T_epsg_world * [x, y, z, 1] (the map frame is the run's world;\n"
      "# grid_scale horizontally, heights unscaled)\n");
  out.print("T_epsg_world:\n");
  const Eigen::Matrix4d T =
      r.T_grid_map.matrix() * Eigen::Vector4d(scale, scale, 1.0, 1.0).asDiagonal();
  for (int i = 0; i < 4; ++i)
    out.print("  - [{}, {}, {}, {}]\n", T(i, 0), T(i, 1), T(i, 2), T(i, 3));
  out.print(
      "# 1-sigma (jackknife over the map's quadrants): east, north, up (m); roll, pitch, "
      "yaw (deg)\n");
  out.print("sigma: [{:.4f}, {:.4f}, {:.4f}, {:.4f}, {:.4f}, {:.4f}]\n", r.sigma[0], r.sigma[1],
            r.sigma[2], r.sigma[3] * kDegPerRad, r.sigma[4] * kDegPerRad, r.sigma[5] * kDegPerRad);
}

}  // namespace

int runAlsGeoref(const AlsGeorefOptions& options) {
  const fs::path run = options.run;
  if (!fs::exists(run / "map.las") || !fs::exists(run / "trajectory.tum"))
    throw InputError(
        fmt::format("{}: expected a run directory with map.las and trajectory.tum", run.string()));
  const Guess guess = startingPose(options);
  const geo::CoordinateConverter converter(guess.epsg);
  // Grid metres per map metre where the map lies (the projection's scale and the height
  // reduction, 0.9996-1.0004 in TM35FIN): the map is scaled horizontally before the rigid
  // registration, as heights are not scaled in the grid.
  const Eigen::Vector3d start = guess.T_grid_map.translation();
  const double scale = converter.gridTangent(converter.fromProjected(start)).scale;
  const Eigen::DiagonalMatrix<double, 3> S(scale, scale, 1.0);
  // Read once: registered in grid metres, then written in the grid.
  PointCloud map = io::readAnyCloudFile(run / "map.las");
  std::vector<Eigen::Vector3d>& map_points = map.positions;
  if (map_points.empty())
    throw InputError(fmt::format("{}: no points", (run / "map.las").string()));
  for (Eigen::Vector3d& p : map_points) p = S * p;

  // The ALS around the map where the guess puts it, wide enough for the search.
  Eigen::AlignedBox2d area;
  for (const Eigen::Vector3d& p : map_points) area.extend((guess.T_grid_map * p).head<2>());
  const double margin_m = guess.search_m + 0.2 * area.sizes().maxCoeff() + 10.0;
  area.min().array() -= margin_m;
  area.max().array() += margin_m;
  std::vector<std::string> tiles;
  const std::vector<fs::path> files = lasFiles(options.als);
  const std::vector<Eigen::Vector3d> als = readAls(files, area, tiles);
  if (tiles.empty())
    throw InputError(fmt::format(
        "no ALS tile of {} overlaps the map where the start puts it (E {:.0f}..{:.0f}, N "
        "{:.0f}..{:.0f}, EPSG:{}; start: {})",
        files.size(), area.min().x(), area.max().x(), area.min().y(), area.max().y(), guess.epsg,
        guess.source));

  const georef::AlsRegistration r =
      georef::registerToAls(map_points, als, guess.T_grid_map,
                            {.search_xy_m = guess.search_m, .search_yaw_deg = guess.search_deg});
  fs::create_directories(options.out);
  writeReport(fs::path(options.out) / "georef_als.yaml", r, guess, scale, tiles);
  fmt::print(
      "als        {} points from {} of {} tiles near the map; {} map points (ground and "
      "crowns)\n",
      als.size(), tiles.size(), files.size(), r.map_points);
  if (!r.ok) {
    fmt::print(stderr, "taiga georef: the map was not registered to the ALS: {}\n", r.reason);
    return kExitFailure;
  }
  // How far the registration moved the map's origin from the start, in the grid.
  const Eigen::Vector3d moved = r.T_grid_map.translation() - guess.T_grid_map.translation();
  const double turned_deg =
      (r.T_grid_map.rotation() * guess.T_grid_map.rotation().inverse()).Log().z() * kDegPerRad;
  fmt::print(
      "registered coverage {:.0f} %, score {:.3f} (next {:.3f}); the map moved {:.2f} m "
      "horizontally, {:.2f} m in height and turned {:.2f} deg from the start ({}, searched "
      "{:.1f} m and {:.1f} deg around it)\n",
      100.0 * r.coverage, r.score, r.second_score, moved.head<2>().norm(), moved.z(), turned_deg,
      guess.source, guess.search_m, guess.search_deg);
  fmt::print(
      "1-sigma    east {:.3f} m, north {:.3f} m, up {:.3f} m, roll {:.3f} deg, pitch {:.3f} "
      "deg, yaw {:.3f} deg\n",
      r.sigma[0], r.sigma[1], r.sigma[2], r.sigma[3] * kDegPerRad, r.sigma[4] * kDegPerRad,
      r.sigma[5] * kDegPerRad);

  // The trajectory and the map in the grid.
  const Trajectory trajectory = io::readTum(run / "trajectory.tum");
  std::vector<georef::GridPose> poses;
  for (const StampedPose& s : trajectory.poses()) {
    const Eigen::Vector3d p = r.T_grid_map * (S * s.pose.translation());
    const Eigen::Matrix3d R = (r.T_grid_map.rotation() * s.pose.rotation()).matrix();
    poses.push_back({s.t_s, p.x(), p.y(), p.z(), std::atan2(R(1, 0), R(0, 0)) * kDegPerRad});
  }
  const fs::path out = options.out;
  georef::writeGridCsv(out / fmt::format("trajectory_epsg{}.csv", guess.epsg), poses);
  georef::writeGeoJson(out / "trajectory.geojson", poses, guess.epsg, "trajectory (ALS)");
  for (Eigen::Vector3d& p : map_points) p = r.T_grid_map * p;  // already scaled by S
  io::LasWriter writer(out / fmt::format("map_epsg{}.las", guess.epsg), {.wkt = converter.wkt()});
  writer.append(map);
  writer.close();
  fmt::print(
      "outputs    {}/ (georef_als.yaml, trajectory_epsg{}.csv, trajectory.geojson, "
      "map_epsg{}.las)\n",
      options.out, guess.epsg, guess.epsg);
  return kExitOk;
}

}  // namespace taiga::app
