#include "taiga/mapping/map_export.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <unordered_map>

#include "taiga/core/errors.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/las_writer.hpp"

namespace taiga::mapping {
namespace {

struct VoxelKey {
  std::int64_t x, y, z;
  bool operator==(const VoxelKey&) const = default;
};

struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    // The usual spatial hash (Teschner et al. 2003): large primes per axis, xor.
    return static_cast<std::size_t>(k.x * 73856093LL) ^ static_cast<std::size_t>(k.y * 19349663LL) ^
           static_cast<std::size_t>(k.z * 83492791LL);
  }
};

/// The point a voxel keeps so far.
struct VoxelPoint {
  Eigen::Vector3d p_out;
  double t_s;
  float intensity;
  std::uint16_t ring;
  std::uint64_t keyframe;
  double distance2_to_centre;
};

/// One point per voxel: the one nearest the voxel's centre over every keyframe added.
class NearestToCentreGrid {
 public:
  explicit NearestToCentreGrid(double voxel_m) : voxel_m_(voxel_m) {}

  void add(const PointCloud& cloud_out, std::uint64_t keyframe) {
    for (std::size_t i = 0; i < cloud_out.size(); ++i) {
      const Eigen::Vector3d& p = cloud_out.positions[i];
      if (!p.allFinite()) continue;
      const Eigen::Vector3d cell = (p / voxel_m_).array().floor();
      const VoxelKey key{static_cast<std::int64_t>(cell.x()), static_cast<std::int64_t>(cell.y()),
                         static_cast<std::int64_t>(cell.z())};
      const double d2 = (p - (cell.array() + 0.5).matrix() * voxel_m_).squaredNorm();
      const VoxelPoint candidate{p,
                                 cloud_out.hasTimes() ? cloud_out.times_s[i] : 0.0,
                                 cloud_out.hasIntensities() ? cloud_out.intensities[i] : 0.0f,
                                 cloud_out.hasRings() ? cloud_out.rings[i] : std::uint16_t{0},
                                 keyframe,
                                 d2};
      const auto [it, inserted] = index_.try_emplace(key, points_.size());
      if (inserted) {
        points_.push_back(candidate);
      } else if (d2 < points_[it->second].distance2_to_centre) {  // ties: the earlier point stays
        points_[it->second] = candidate;
      }
    }
  }

  /// The kept points grouped by keyframe (in first-occupied order within a keyframe).
  std::vector<VoxelPoint> takePoints() {
    index_.clear();
    std::stable_sort(points_.begin(), points_.end(), [](const VoxelPoint& a, const VoxelPoint& b) {
      return a.keyframe < b.keyframe;
    });
    return std::move(points_);
  }

 private:
  double voxel_m_;
  std::unordered_map<VoxelKey, std::size_t, VoxelKeyHash> index_;
  std::vector<VoxelPoint> points_;
};

/// Output of one keyframe: to the LAS file now, and to the PLY cloud when asked.
class MapSink {
 public:
  MapSink(const std::filesystem::path& las_path, const MapExportOptions& options)
      : las_(las_path, io::LasOptions{.wkt = options.wkt}), write_ply_(options.write_ply) {}

  void append(const PointCloud& cloud_out, std::uint64_t keyframe) {
    if (cloud_out.empty()) return;
    las_.append(cloud_out, static_cast<std::uint16_t>(keyframe % 65536));
    if (write_ply_) ply_.append(cloud_out);
  }

  std::uint64_t finish(const std::filesystem::path& ply_path) {
    las_.close();
    if (write_ply_) io::writePly(ply_path, ply_);
    return las_.pointCount();
  }

 private:
  io::LasWriter las_;
  bool write_ply_;
  PointCloud ply_;
};

/// Keeps the channels the LAS and PLY outputs carry (positions, times, intensities, rings).
PointCloud toOutputFrame(PointCloud cloud_in_body, const Eigen::Affine3d& T_out_body) {
  for (Eigen::Vector3d& p : cloud_in_body.positions) p = T_out_body * p;
  cloud_in_body.columns.clear();
  return cloud_in_body;
}

void appendVoxelPoints(MapSink& sink, std::vector<VoxelPoint> points, bool has_times,
                       bool has_intensities, bool has_rings) {
  PointCloud chunk;
  auto flush = [&](std::uint64_t keyframe) {
    sink.append(chunk, keyframe);
    chunk.clear();
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    const VoxelPoint& v = points[i];
    if (i > 0 && v.keyframe != points[i - 1].keyframe) flush(points[i - 1].keyframe);
    chunk.positions.push_back(v.p_out);
    if (has_times) chunk.times_s.push_back(v.t_s);
    if (has_intensities) chunk.intensities.push_back(v.intensity);
    if (has_rings) chunk.rings.push_back(v.ring);
  }
  if (!points.empty()) flush(points.back().keyframe);
}

}  // namespace

MapExportSummary exportMap(const KeyframeStore& store,
                           const std::vector<lie::SE3>& poses_T_map_body,
                           const std::filesystem::path& las_path, const MapExportOptions& options) {
  if (poses_T_map_body.size() != store.size())
    throw std::invalid_argument(
        fmt::format("exportMap: {} poses for {} keyframes", poses_T_map_body.size(), store.size()));
  if (!(options.voxel_m >= 0.0) || !std::isfinite(options.voxel_m))
    throw InputError(fmt::format("--map-voxel {}: expected a voxel size >= 0 m", options.voxel_m));

  MapSink sink(las_path, options);
  std::optional<NearestToCentreGrid> grid;
  if (options.voxel_m > 0.0) grid.emplace(options.voxel_m);
  MapExportSummary summary;
  bool has_times = false, has_intensities = false, has_rings = false;
  for (std::uint64_t id = 0; id < store.size(); ++id) {
    if (options.keep && !options.keep(id)) continue;
    const PointCloud cloud_out = toOutputFrame(
        store.load(id), options.T_out_map * Eigen::Affine3d(poses_T_map_body[id].matrix()));
    summary.points_read += cloud_out.size();
    ++summary.keyframes;
    if (!grid) {
      sink.append(cloud_out, id);
      continue;
    }
    if (!cloud_out.empty()) {
      has_times = cloud_out.hasTimes();
      has_intensities = cloud_out.hasIntensities();
      has_rings = cloud_out.hasRings();
    }
    grid->add(cloud_out, id);
  }
  if (grid) appendVoxelPoints(sink, grid->takePoints(), has_times, has_intensities, has_rings);
  std::filesystem::path ply_path = las_path;
  ply_path.replace_extension(".ply");
  summary.points_written = sink.finish(ply_path);
  return summary;
}

}  // namespace taiga::mapping
