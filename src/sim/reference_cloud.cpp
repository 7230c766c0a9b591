#include "taiga/sim/reference_cloud.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <tuple>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/las_writer.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {
constexpr double kPi = std::numbers::pi;
/// Rows of one station cast and thinned together (bounds the memory of the raw samples).
constexpr int kRowsPerChunk = 64;

void validate(const ReferenceCloudParams& p) {
  auto fail = [](const std::string& what) { throw InputError("reference cloud: " + what); };
  if (!(p.station_spacing_m > 0.0))
    fail(fmt::format("station_spacing_m: expected > 0, found {}", p.station_spacing_m));
  if (!(p.angular_step_deg >= 0.005 && p.angular_step_deg <= 5.0))
    fail(fmt::format("angular_step_deg: expected 0.005 .. 5, found {}", p.angular_step_deg));
  if (!(p.max_range_m > 0.0))
    fail(fmt::format("max_range_m: expected > 0, found {}", p.max_range_m));
  if (!(p.min_elevation_deg >= -90.0 && p.min_elevation_deg < 90.0))
    fail(fmt::format("min_elevation_deg: expected -90 .. 90, found {}", p.min_elevation_deg));
  if (!(p.voxel_m >= 0.0)) fail(fmt::format("voxel_m: expected >= 0, found {}", p.voxel_m));
}

struct Sample {
  std::uint64_t key;  ///< voxel index (or the sample's order when not thinning)
  double d2;          ///< squared distance to the voxel centre
  Eigen::Vector3d p_world;
  float intensity;
  std::uint16_t station;
};

/// Total order: the voxel, then the sample nearest its centre (ties broken by position and
/// station), so the kept sample does not depend on the order in which samples arrive.
bool before(const Sample& a, const Sample& b) {
  return std::tie(a.key, a.d2, a.p_world.x(), a.p_world.y(), a.p_world.z(), a.station) <
         std::tie(b.key, b.d2, b.p_world.x(), b.p_world.y(), b.p_world.z(), b.station);
}

/// Sorts and keeps the first sample of each voxel.
void thin(std::vector<Sample>& samples) {
  std::sort(samples.begin(), samples.end(), before);
  samples.erase(std::unique(samples.begin(), samples.end(),
                            [](const Sample& a, const Sample& b) { return a.key == b.key; }),
                samples.end());
}

/// Elevation of every row and the number of azimuth samples in it.
std::vector<std::pair<double, int>> rowsOf(const ReferenceCloudParams& params) {
  std::vector<std::pair<double, int>> rows;
  const double step = params.angular_step_deg;
  for (double el = params.min_elevation_deg; el < 90.0; el += step) {
    // A uniform angular density: step / cos(elevation) in azimuth.
    const int n_az =
        std::max(1, static_cast<int>(std::lround(360.0 * std::cos(el * kRadPerDeg) / step)));
    rows.emplace_back(el * kRadPerDeg, n_az);
  }
  return rows;
}
}  // namespace

std::vector<Eigen::Vector3d> referenceStations(const Simulation& simulation,
                                               const ReferenceCloudParams& params) {
  validate(params);
  const Terrain& terrain = simulation.scene().terrain();
  auto stationAt = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(p.x(), p.y(), terrain.height(p.x(), p.y()) + params.station_height_m);
  };
  std::vector<Eigen::Vector3d> stations;
  const double dt = 0.1;
  Eigen::Vector3d last = simulation.motion().at(0.0).T_world_body.translation();
  stations.push_back(stationAt(last));
  double travelled_m = 0.0;
  for (double t = dt; t <= simulation.duration_s(); t += dt) {
    const Eigen::Vector3d p = simulation.motion().at(t).T_world_body.translation();
    travelled_m += (p - last).head<2>().norm();
    last = p;
    if (travelled_m >= params.station_spacing_m) {
      stations.push_back(stationAt(p));
      travelled_m = 0.0;
    }
  }
  return stations;
}

PointCloud simulateReferenceCloud(const Scene& scene, const std::vector<Eigen::Vector3d>& stations,
                                  const ReferenceCloudParams& params) {
  validate(params);
  const auto rows = rowsOf(params);
  const SceneLayout& layout = scene.layout();
  // Voxel indices from a corner well outside the plot, 21 bits per axis (42 km at 2 cm).
  const Eigen::Vector3d corner(layout.center_world.x() - layout.half_size_m - 100.0,
                               layout.center_world.y() - layout.half_size_m - 100.0,
                               -1000.0);
  const bool thinning = params.voxel_m > 0.0;
  std::vector<Sample> kept;
  std::uint64_t order = 0;
  for (std::size_t s = 0; s < stations.size(); ++s) {
    const Eigen::Vector3d& origin = stations[s];
    std::vector<Sample> station_samples;
    for (std::size_t first = 0; first < rows.size(); first += kRowsPerChunk) {
      const std::size_t last = std::min(rows.size(), first + kRowsPerChunk);
      std::vector<std::vector<Sample>> per_row(last - first);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(first, last, 1), [&](const auto& range) {
        std::vector<Eigen::Vector3d> dirs;
        std::vector<std::optional<RayHit>> hits;
        for (std::size_t r = range.begin(); r != range.end(); ++r) {
          const auto [el, n_az] = rows[r];
          dirs.resize(static_cast<std::size_t>(n_az));
          for (int j = 0; j < n_az; ++j) {
            const double az = 2.0 * kPi * j / n_az;
            dirs[static_cast<std::size_t>(j)] = Eigen::Vector3d(
                std::cos(az) * std::cos(el), std::sin(az) * std::cos(el), std::sin(el));
          }
          scene.castRays(origin, dirs, params.max_range_m, hits);
          std::vector<Sample>& out = per_row[r - first];
          for (std::size_t j = 0; j < dirs.size(); ++j) {
            if (!hits[j]) continue;
            const Eigen::Vector3d p = origin + hits[j]->range_m * dirs[j];
            const double cos_inc = std::max(0.05, std::abs(hits[j]->normal_world.dot(dirs[j])));
            Sample sample{0, 0.0, p,
                          static_cast<float>(100.0 * reflectivity(hits[j]->material) * cos_inc),
                          static_cast<std::uint16_t>(s)};
            if (thinning) {
              const Eigen::Vector3d cell = ((p - corner) / params.voxel_m).array().floor();
              const Eigen::Vector3d centre = corner + (cell.array() + 0.5).matrix() * params.voxel_m;
              sample.d2 = (p - centre).squaredNorm();
              const auto ix = static_cast<std::uint64_t>(cell.x()) & 0x1FFFFF;
              const auto iy = static_cast<std::uint64_t>(cell.y()) & 0x1FFFFF;
              const auto iz = static_cast<std::uint64_t>(cell.z()) & 0x1FFFFF;
              sample.key = (ix << 42) | (iy << 21) | iz;
            }
            out.push_back(sample);
          }
        }
      });
      for (std::vector<Sample>& row : per_row) {  // in row order: deterministic
        if (!thinning)
          for (Sample& sample : row) sample.key = order++;
        station_samples.insert(station_samples.end(), row.begin(), row.end());
      }
      if (thinning) thin(station_samples);
    }
    kept.insert(kept.end(), station_samples.begin(), station_samples.end());
    if (thinning) thin(kept);
  }
  PointCloud cloud;
  cloud.reserve(kept.size());
  for (const Sample& sample : kept) {
    cloud.positions.push_back(sample.p_world);
    cloud.times_s.push_back(0.0);
    cloud.intensities.push_back(sample.intensity);
    cloud.rings.push_back(sample.station);
    cloud.columns.push_back(0);
  }
  return cloud;
}

ReferenceCloudSummary writeReferenceCloud(const Simulation& simulation,
                                          const std::filesystem::path& path,
                                          const ReferenceCloudParams& params) {
  const std::vector<Eigen::Vector3d> stations = referenceStations(simulation, params);
  const PointCloud cloud = simulateReferenceCloud(simulation.scene(), stations, params);
  ReferenceCloudSummary summary;
  summary.stations = stations.size();
  for (const auto& row : rowsOf(params)) summary.rays += static_cast<std::size_t>(row.second);
  summary.rays *= stations.size();
  summary.points = cloud.size();
  {
    io::LasWriter writer(path);
    writer.append(cloud);
    writer.close();
  }
  summary.file_bytes = std::filesystem::file_size(path);
  return summary;
}

}  // namespace taiga::sim
