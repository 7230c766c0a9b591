#include "taiga/sim/als.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/io/las_writer.hpp"
#include "taiga/sim/georef_truth.hpp"
#include "taiga/sim/random.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

constexpr std::uint8_t kGroundClass = 2, kUnclassified = 1;

void validate(const AlsParams& p) {
  const auto fail = [](const std::string& what) { throw InputError("ALS: " + what); };
  if (!(p.pulses_per_m2 > 0.0 && p.pulses_per_m2 <= 1000.0))
    fail(fmt::format("pulses_per_m2: expected 0 .. 1000, found {}", p.pulses_per_m2));
  if (!(p.altitude_m >= 50.0))
    fail(fmt::format("altitude_m: expected >= 50, found {}", p.altitude_m));
  if (!(p.half_swath_deg >= 0.0 && p.half_swath_deg < 60.0))
    fail(fmt::format("half_swath_deg: expected 0 .. 60, found {}", p.half_swath_deg));
  if (!(p.footprint_radius_m >= 0.0)) fail("footprint_radius_m: expected >= 0");
  if (p.rays_per_pulse < 1 || p.rays_per_pulse > 64)
    fail(fmt::format("rays_per_pulse: expected 1 .. 64, found {}", p.rays_per_pulse));
  if (!(p.range_sigma_m >= 0.0 && p.horizontal_sigma_m >= 0.0)) fail("noise sigmas: expected >= 0");
}

struct Return {
  Eigen::Vector3d p_world;
  float intensity;
  bool ground;
};

/// One pulse's returns: the nearest and, when far enough beyond it, the farthest surface its
/// footprint's rays meet.
struct Pulse {
  std::optional<Return> first, last;
};

Pulse castPulse(const Scene& scene, const Eigen::Vector3d& target_world, double z_flight_m,
                const AlsParams& p, std::uint64_t seed, std::uint64_t index) {
  const double off_nadir =
      (2.0 * hashUniform(seed, index, 2) - 1.0) * p.half_swath_deg * kRadPerDeg;
  // Flight lines along world y: the aircraft is displaced across track (x) from the target.
  const Eigen::Vector3d air(
      target_world.x() + (z_flight_m - target_world.z()) * std::tan(off_nadir), target_world.y(),
      z_flight_m);
  const Eigen::Vector3d beam = (target_world - air).normalized();
  const Eigen::Vector3d e1 = beam.unitOrthogonal(), e2 = beam.cross(e1);
  const double t_max_m = 2.0 * (air - target_world).norm();

  struct Hit {
    double range_m;
    Eigen::Vector3d direction;
    RayHit hit;
  };
  std::optional<Hit> nearest, farthest;
  for (int k = 0; k < p.rays_per_pulse; ++k) {
    // Uniform over the footprint's disc (the first ray at its centre).
    const double r =
        k == 0 ? 0.0 : p.footprint_radius_m * std::sqrt(hashUniform(seed, index, 3, k));
    const double phi = 2.0 * std::numbers::pi * hashUniform(seed, index, 4, k);
    const Eigen::Vector3d aim = target_world + r * (std::cos(phi) * e1 + std::sin(phi) * e2);
    const Eigen::Vector3d direction = (aim - air).normalized();
    const std::optional<RayHit> hit = scene.castRay(air, direction, 0.0, t_max_m);
    if (!hit) continue;
    const Hit h{hit->range_m, direction, *hit};
    if (!nearest || h.range_m < nearest->range_m) nearest = h;
    if (!farthest || h.range_m > farthest->range_m) farthest = h;
  }
  Pulse pulse;
  if (!nearest) return pulse;
  // The aircraft's position and boresight error moves every return of the pulse alike.
  const Eigen::Vector3d shift(p.horizontal_sigma_m * hashNormal(seed, index, 5, 0),
                              p.horizontal_sigma_m * hashNormal(seed, index, 5, 1), 0.0);
  const auto toReturn = [&](const Hit& h, int which) {
    const double range_m = h.range_m + p.range_sigma_m * hashNormal(seed, index, 6, which);
    const double cos_incidence = std::abs(h.direction.dot(h.hit.normal_world));
    return Return{air + range_m * h.direction + shift,
                  static_cast<float>(100.0 * reflectivity(h.hit.material) * cos_incidence),
                  h.hit.material == Material::kGround};
  };
  pulse.first = toReturn(*nearest, 0);
  if (farthest->range_m - nearest->range_m > p.min_return_separation_m)
    pulse.last = toReturn(*farthest, 1);
  return pulse;
}

}  // namespace

AlsReturns simulateAls(const Scene& scene, const Eigen::Vector2d& center_world, double half_size_m,
                       const AlsParams& params, std::uint64_t seed) {
  validate(params);
  if (!(half_size_m > 0.0)) throw InputError("ALS: the area's half size must be positive");
  const double area_m2 = 4.0 * half_size_m * half_size_m;
  const std::size_t n = static_cast<std::size_t>(std::llround(params.pulses_per_m2 * area_m2));
  const std::uint64_t stream = streamSeed(seed, "als");
  const Terrain& terrain = scene.terrain();
  const double z_flight_m =
      terrain.smoothHeight(center_world.x(), center_world.y()) + params.altitude_m;

  std::vector<Pulse> pulses(n);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, 4096),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          const double x = center_world.x() + (2.0 * hashUniform(stream, i, 0) - 1.0) * half_size_m;
          const double y = center_world.y() + (2.0 * hashUniform(stream, i, 1) - 1.0) * half_size_m;
          const Eigen::Vector3d target(x, y, terrain.smoothHeight(x, y));
          pulses[i] = castPulse(scene, target, z_flight_m, params, stream, i);
        }
      });

  AlsReturns out;
  out.pulses = n;
  const auto add = [&out](const Return& r, std::uint8_t number, std::uint8_t of) {
    out.cloud.positions.push_back(r.p_world);
    out.cloud.intensities.push_back(r.intensity);
    out.classifications.push_back(r.ground ? kGroundClass : kUnclassified);
    out.returns.push_back({number, of});
  };
  for (const Pulse& pulse : pulses) {
    if (!pulse.first) continue;
    const std::uint8_t of = pulse.last ? 2 : 1;
    add(*pulse.first, 1, of);
    if (pulse.last) add(*pulse.last, 2, 2);
  }
  return out;
}

AlsSummary writeAls(const Simulation& simulation, const std::filesystem::path& path,
                    const AlsParams& params) {
  const SceneLayout& layout = simulation.scene().layout();
  AlsReturns als = simulateAls(simulation.scene(), layout.center_world, layout.half_size_m, params,
                               simulation.seed());
  const GeorefTruth truth = georefTruth(simulation.scenario().gnss);
  for (Eigen::Vector3d& p : als.cloud.positions)
    p = (truth.T_epsg_world * p.homogeneous()).head<3>();

  AlsSummary summary;
  summary.pulses = als.pulses;
  summary.points = als.cloud.size();
  summary.area_m2 = 4.0 * layout.half_size_m * layout.half_size_m;
  for (const auto& r : als.returns) summary.last_returns += r[0] == 2 ? 1 : 0;
  for (std::uint8_t c : als.classifications) summary.ground_points += c == kGroundClass ? 1 : 0;
  {
    io::LasWriter writer(path, {.wkt = geo::CoordinateConverter(truth.epsg).wkt()});
    writer.append(als.cloud, {.classifications = als.classifications, .returns = als.returns});
    writer.close();
  }
  summary.file_bytes = std::filesystem::file_size(path);
  return summary;
}

}  // namespace taiga::sim
