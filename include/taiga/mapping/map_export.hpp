#pragma once
// The forest model (issue 7, item 3): every keyframe's full-resolution deskewed scan, read back
// from the keyframe store one keyframe at a time, transformed by its pose into map.las
// (io/las_writer.hpp: intensity, GPS time = the point's time, user data = ring, point source
// ID = keyframe id mod 65536), and optionally map.ply next to it.
//
// Decimation (voxel_m > 0) is global across keyframes: one point per cubic voxel of the output
// frame, the measured point nearest to the voxel's centre, with its own time, intensity, ring and
// keyframe (as PDAL's filters.voxelcenternearestneighbor). Unlike a per-keyframe filter, a tree
// seen from 50 keyframes is not kept 50 times. Ties go to the earlier keyframe, so the result does
// not depend on anything but the store and the poses. Memory: about 170 B per output point (a
// hash-map entry and a record per occupied voxel); the full-resolution scans are streamed (one
// keyframe in RAM at a time). Without decimation nothing but one keyframe is held, except for
// map.ply, which is written at the end from the whole map in RAM (as io::writePly needs).

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/mapping/keyframe_store.hpp"

namespace taiga::mapping {

struct MapExportOptions {
  double voxel_m = 0.0;    ///< > 0: one point per voxel of this edge, m (`--map-voxel`)
  bool write_ply = false;  ///< also the same points as binary PLY (las path with .ply)
  /// Output frame: p_out = T_out_map * T_map_body * p_body; affine, so that it can carry a
  /// projected grid's scale factor (e.g. a georeferencing's T_epsg_world; identity: the map in
  /// the map frame).
  Eigen::Affine3d T_out_map = Eigen::Affine3d::Identity();
  std::string wkt;  ///< OGC WKT of the output frame for the LAS header; empty: local coordinates
  /// Which keyframes (by id) to export; empty: all (e.g. one map segment of a run).
  std::function<bool(std::uint64_t id)> keep;
};

struct MapExportSummary {
  std::size_t keyframes = 0;
  std::uint64_t points_read = 0;     ///< full-resolution points of all keyframes
  std::uint64_t points_written = 0;  ///< after decimation
};

/// Writes the map of `store` with `poses_T_map_body` (one per keyframe, in id order) to
/// `las_path`. InputError when a keyframe file is unreadable or the output cannot be written.
MapExportSummary exportMap(const KeyframeStore& store,
                           const std::vector<lie::SE3>& poses_T_map_body,
                           const std::filesystem::path& las_path,
                           const MapExportOptions& options = {});

}  // namespace taiga::mapping
