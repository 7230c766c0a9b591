// taiga trees: the forest inventory of a map (docs/trees.md): ground, DTM, stems, DBH, a tree
// list and a classified map, from a run directory or any LAS/PLY/PCD cloud.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

#include "command.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/georef/georef_files.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/las_writer.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/pipeline/thread_limit.hpp"
#include "taiga/trees/inventory.hpp"
#include "taiga/trees/tree_files.hpp"

namespace taiga::app {
namespace {
namespace fs = std::filesystem;

struct TreesOptions {
  std::string input, out;
  double dtm_cell_m = 0.5;
  double min_dbh_m = 0.07;
  double breast_height_m = 1.3;
  double max_fit_rms_m = 0.045;
  int epsg = 0;
  int threads = 0;  // 0: one per core
  bool no_map = false;
};

PointCloud readCloud(const fs::path& path) {
  std::size_t skipped = 0;
  PointCloud cloud = io::readAnyCloudFile(path, &skipped);
  if (skipped > 0)
    fmt::print(stderr,
               "taiga trees: {}: {} points with NaN, infinite or zero coordinates skipped\n",
               path.string(), skipped);
  return cloud;
}

// Points are shifted to a round offset near them, so projected coordinates (millions of metres)
// do not cost precision or overflow the grids' integer cells.
Eigen::Vector3d roundOffset(const std::vector<Eigen::Vector3d>& points_m) {
  for (const Eigen::Vector3d& p : points_m)
    if (p.allFinite()) return (p / 100.0).array().floor() * 100.0;
  return Eigen::Vector3d::Zero();
}

// The sensor positions of a run's map.las (local coordinates, like the points): the keyframes',
// and for each point the first keyframe stamped at or after the point's time (a keyframe carries
// its scan's end time). None when the map has no point times or the run no keyframes.tum;
// unknown (that point's residual stays across the surface) for a time no keyframe's scan can
// hold, e.g. the zeros of a recording without per-point times.
struct KeyframeViewpoints {
  std::vector<Eigen::Vector3d> positions_m;
  std::vector<std::uint32_t> of_point;
  trees::Viewpoints view() const { return {positions_m, of_point}; }
};
KeyframeViewpoints keyframeViewpoints(const fs::path& run_dir, const PointCloud& map,
                                      const Eigen::Vector3d& offset_m) {
  const fs::path keyframes_tum = run_dir / "keyframes.tum";
  if (!map.hasTimes() || !fs::exists(keyframes_tum)) return {};
  const Trajectory keyframes = io::readTum(keyframes_tum);
  if (keyframes.empty()) return {};
  KeyframeViewpoints viewpoints;
  for (const StampedPose& k : keyframes)
    viewpoints.positions_m.push_back(k.pose.translation() - offset_m);
  viewpoints.of_point.resize(map.size());
  for (std::size_t i = 0; i < map.size(); ++i) {
    const auto after =
        std::lower_bound(keyframes.begin(), keyframes.end(), map.times_s[i],
                         [](const StampedPose& k, double t_s) { return k.t_s < t_s; });
    constexpr double kLongestScan_s = 1.0;
    viewpoints.of_point[i] =
        after != keyframes.end() && after->t_s - map.times_s[i] <= kLongestScan_s
            ? static_cast<std::uint32_t>(after - keyframes.begin())
            : trees::Viewpoints::kUnknown;
  }
  return viewpoints;
}

int runTrees(const TreesOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const fs::path input = options.input;
  const bool run_dir = fs::is_directory(input);
  const fs::path map_path = run_dir ? input / "map.las" : input;
  if (run_dir && !fs::exists(map_path))
    throw InputError(
        fmt::format("{}: a directory without map.las (give a run directory of `taiga "
                    "run`, or a LAS/PLY/PCD file)",
                    input.string()));
  const fs::path out = !options.out.empty() ? fs::path(options.out)
                       : run_dir            ? input
                                            : input.parent_path();
  fs::create_directories(out.empty() ? "." : out);

  PointCloud cloud = readCloud(map_path);
  if (cloud.empty())
    throw InputError(fmt::format("{}: the cloud has no points", map_path.string()));
  const Eigen::Vector3d offset_m = roundOffset(cloud.positions);
  std::vector<Eigen::Vector3d> local(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) local[i] = cloud.positions[i] - offset_m;

  std::optional<trees::GridFrame> grid;
  std::string wkt;
  const fs::path georef_yaml = input / "georef" / "georef.yaml";
  if (options.epsg > 0) {
    // The cloud is already in the grid.
    const geo::CoordinateConverter crs(options.epsg);
    wkt = crs.wkt();
    grid = trees::GridFrame{options.epsg, Eigen::Affine3d(Eigen::Translation3d(offset_m))};
  } else if (run_dir && fs::exists(georef_yaml)) {
    const georef::GeorefGrid g = georef::readGeorefGrid(georef_yaml);
    grid =
        trees::GridFrame{g.epsg, Eigen::Affine3d(g.T_epsg_world) * Eigen::Translation3d(offset_m)};
  }

  trees::InventoryOptions io_options;
  io_options.terrain.cell_m = options.dtm_cell_m;
  io_options.stems.min_dbh_m = options.min_dbh_m;
  io_options.stems.breast_height_m = options.breast_height_m;
  io_options.stems.max_fit_rms_m = options.max_fit_rms_m;
  io_options.stems.parallel = true;
  // A run's map knows where its sensor was: the DBH fit measures range noise along the beams.
  const KeyframeViewpoints viewpoints = run_dir && options.epsg == 0
                                            ? keyframeViewpoints(input, cloud, offset_m)
                                            : KeyframeViewpoints{};
  const pipeline::ThreadLimit thread_limit(options.threads);
  const trees::Inventory inventory = trees::takeInventory(local, io_options, viewpoints.view());
  const std::vector<trees::Stem>& stems = inventory.stems;

  trees::writeTreesCsv(out / "trees.csv", stems, offset_m, grid);
  trees::writeTreesGeoJson(out / "trees.geojson", stems, offset_m, grid);
  trees::writeAsciiGrid(out / "dtm.asc", inventory.terrain, offset_m);
  if (!options.no_map) {
    const trees::PointLabels labels = trees::labelPoints(local, inventory, io_options.terrain);
    // Every point's height above the DTM, as a LAS extra field (the height-normalised map that
    // lidR's normalize_height or 3DFin work on).
    std::vector<float> above_ground_m(local.size());
    for (std::size_t i = 0; i < local.size(); ++i)
      above_ground_m[i] =
          static_cast<float>(local[i].z() - inventory.terrain.heightAt(local[i].x(), local[i].y()));
    io::LasWriter writer(out / "trees_map.las",
                         {.wkt = wkt,
                          .extra_float_name = "HeightAboveGround",
                          .extra_float_description = "height above the DTM, m"});
    writer.append(cloud, {.classifications = labels.classification,
                          .source_ids = labels.tree_id,
                          .extra = above_ground_m});
    writer.close();
  }

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::size_t good = 0, partial = 0;
  for (const trees::Stem& s : stems) {
    good += s.quality == trees::StemQuality::kGood;
    partial += s.quality == trees::StemQuality::kPartial;
  }
  fmt::print("input      {} ({} points)\n", map_path.string(), cloud.size());
  fmt::print("terrain    {} x {} cells of {} m, {} with ground points\n", inventory.terrain.nx(),
             inventory.terrain.ny(), inventory.terrain.cellSize(),
             inventory.terrain.measuredCells());
  fmt::print("stems      {} ({} good, {} seen from one side, {} poor){}\n", stems.size(), good,
             partial, stems.size() - good - partial,
             grid ? fmt::format("; in EPSG:{}", grid->epsg) : "");
  const auto with_sensor =
      std::count_if(viewpoints.of_point.begin(), viewpoints.of_point.end(),
                    [](std::uint32_t k) { return k != trees::Viewpoints::kUnknown; });
  if (with_sensor == 0)
    fmt::print(
        "DBH fit    residuals across the surface (no sensor positions: not a taiga run, or "
        "a map without point times)\n");
  else
    fmt::print(
        "DBH fit    residuals along the beams for {} of {} points (the sensor at their "
        "keyframe), across the surface for the others; kept along the beams for {} of {} "
        "stems (the others' views do not meet well enough: docs/trees.md)\n",
        with_sensor, local.size(),
        std::count_if(stems.begin(), stems.end(),
                      [](const trees::Stem& s) { return s.dbh_along_beams; }),
        stems.size());
  if (stems.empty())
    fmt::print(
        "           none found: heights are measured from the lowest points of each {} m "
        "cell, so a cloud without ground (a slice, a tree cut above its base) has no "
        "breast height\n",
        inventory.terrain.cellSize());
  fmt::print("outputs    {}/ (trees.csv, trees.geojson, dtm.asc{}) in {:.1f} s\n", out.string(),
             options.no_map ? "" : ", trees_map.las", seconds);
  return kExitOk;
}
}  // namespace

Command addTreesCommand(CLI::App& tool) {
  auto options = std::make_shared<TreesOptions>();
  CLI::App* parser = tool.add_subcommand(
      "trees", "Forest inventory of a map: ground, DTM, stems, DBH, tree list (docs/trees.md)");
  parser
      ->add_option("INPUT", options->input,
                   "A run directory (its map.las, and georef/ when there is one) or a "
                   "LAS/PLY/PCD cloud (e.g. a TLS plot)")
      ->required()
      ->check(CLI::ExistingPath);
  parser->add_option("--out", options->out,
                     "Output directory (default: the run directory, or the cloud's directory)");
  parser->add_option("--dtm-cell", options->dtm_cell_m, "DTM cell size, m")
      ->check(CLI::Range(0.1, 5.0));
  parser->add_option("--min-dbh", options->min_dbh_m, "Thinner stems are not reported, m")
      ->check(CLI::Range(0.02, 1.0));
  parser
      ->add_option("--breast-height", options->breast_height_m,
                   "Height above the ground where the DBH is measured, m")
      ->check(CLI::Range(0.5, 3.0));
  parser
      ->add_option("--max-fit-rms", options->max_fit_rms_m,
                   "Stem cross-sections whose points scatter more are not stems, m (2/3 of it "
                   "for stems tracked over less than 2.7 m)")
      ->check(CLI::Range(0.005, 0.2));
  parser
      ->add_option("--epsg", options->epsg,
                   "The cloud's coordinates are in this projected CRS (trees.csv and "
                   "trees.geojson carry it)")
      ->check(CLI::PositiveNumber);
  parser->add_option("--threads", options->threads, "Threads for the stem fits, 0: one per core")
      ->check(CLI::NonNegativeNumber);
  parser->add_flag("--no-map", options->no_map, "Do not write the classified trees_map.las");
  return {parser, [options] { return runTrees(*options); }, options};
}

}  // namespace taiga::app
