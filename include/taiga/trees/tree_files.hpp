#pragma once
// The tree list's files (docs/trees.md, "Outputs"): trees.csv and trees.geojson out, and any
// trees.csv in (taiga's own, or the simulator's ground truth) for the evaluation.

#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "taiga/trees/stem_detection.hpp"

namespace taiga::trees {

/// Where the stems' local coordinates lie in a projected grid: [E, N, h] = T_epsg_local * p.
struct GridFrame {
  int epsg = 0;
  Eigen::Affine3d T_epsg_local = Eigen::Affine3d::Identity();
};

/// trees.csv, one row per stem, header
/// `id,x_m,y_m,z_m,x_bh_m,y_bh_m,dbh_m,dbh_sigma_m,height_m,lean_deg,lean_azimuth_deg,points,
/// fit_rms_m,arc_deg,slices,quality` and, with a grid, `easting_m,northing_m,ground_height_m`
/// (the stem at breast height, the ground under it). (x, y, z) is the stem axis at the ground, as
/// in the simulator's trees.csv; (x_bh, y_bh) the axis at breast height. The stems' coordinates
/// are local; `offset_m` is added to every coordinate written (x, y, z columns).
void writeTreesCsv(const std::filesystem::path& path, std::span<const Stem> stems,
                   const Eigen::Vector3d& offset_m, const std::optional<GridFrame>& grid);

/// trees.geojson: a FeatureCollection of points (the stems at breast height) with id, DBH (m and
/// cm), height, quality. In the grid (with the 2008 GeoJSON "crs" member naming the EPSG code, as
/// QGIS reads it) when there is one, else in the map frame's x, y (no "crs": local coordinates).
void writeTreesGeoJson(const std::filesystem::path& path, std::span<const Stem> stems,
                       const Eigen::Vector3d& offset_m, const std::optional<GridFrame>& grid);

/// A row of any trees.csv, as the evaluation needs it. Fields a file lacks are NaN.
struct TreeRecord {
  long id = 0;
  Eigen::Vector2d bh_xy_m;  ///< x_bh_m, y_bh_m; or x_m, y_m when the file has no breast height
  double ground_z_m = 0.0;  ///< z_m
  double dbh_m = 0.0;
  double height_m = 0.0;
  double dbh_sigma_m = 0.0;
  double lean_deg = 0.0;          ///< the axis' angle from vertical
  double lean_azimuth_deg = 0.0;  ///< the direction it leans toward, from +x toward +y
};

/// Reads a trees.csv by its header's column names (id, x_m, y_m, dbh_m required; x_bh_m, y_bh_m,
/// z_m, dbh_sigma_m, height_m, lean_deg, lean_azimuth_deg used when present). InputError naming the
/// file, line and column otherwise.
std::vector<TreeRecord> readTreesCsv(const std::filesystem::path& path);
/// The same from a file's text (tests, fuzzing); `source` names it in messages.
std::vector<TreeRecord> parseTreesCsv(const std::string& text, const std::string& source);

}  // namespace taiga::trees
