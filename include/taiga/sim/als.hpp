#pragma once
// Airborne laser scanning (ALS) of a simulated plot (issue 23, docs/simulator.md "ALS"): what a
// survey aircraft records over the forest, the reference that a ground map is registered to in a
// national grid. Modelled on national campaigns (Finland's NLS: 5 or more pulses per m^2, first
// and last returns, classified ground, ETRS-TM35FIN):
// - pulses spread uniformly over the plot (Poisson-like: random positions at the given density),
//   each from the aircraft at `altitude_m` above the terrain's origin, looking down at up to
//   `half_swath_deg` off nadir across the flight lines (which run along world y);
// - a pulse's footprint is sampled by `rays_per_pulse` rays within `footprint_radius_m`: the first
//   return is the nearest surface they meet, the last the farthest, reported when it lies more
//   than `min_return_separation_m` beyond the first (the canopy let part of the beam through to
//   the ground below); otherwise one return;
// - noise: `range_sigma_m` along the beam per return, `horizontal_sigma_m` per pulse (the
//   aircraft's trajectory and boresight error);
// - ground returns (the terrain) classified 2, all others 1, as delivered ALS is;
// - intensity: the material's reflectivity x cos(incidence), in percent, as the lidar's;
// - coordinates in the projected CRS of the simulation's georeference (georef_truth.yaml,
//   T_epsg_world): large numbers, as real tiles have.
// Deterministic and independent of the thread count (counter-based noise per pulse).

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "taiga/core/point_cloud.hpp"
#include "taiga/sim/scene.hpp"

namespace taiga::sim {

class Simulation;

struct AlsParams {
  double pulses_per_m2 = 5.0;
  double altitude_m = 800.0;
  double half_swath_deg = 20.0;
  double footprint_radius_m = 0.2;  ///< 0.5 mrad divergence at 800 m
  int rays_per_pulse = 4;
  double min_return_separation_m = 2.0;
  double range_sigma_m = 0.03;
  double horizontal_sigma_m = 0.05;
};

/// Returns of the pulses, world frame.
struct AlsReturns {
  PointCloud cloud;                                  ///< positions and intensities
  std::vector<std::uint8_t> classifications;         ///< 2 ground, 1 other
  std::vector<std::array<std::uint8_t, 2>> returns;  ///< return number, number of returns
  std::size_t pulses = 0;
};

/// The returns of pulses over the square [center - half_size, center + half_size]^2 (world x, y).
/// InputError for invalid params.
AlsReturns simulateAls(const Scene& scene, const Eigen::Vector2d& center_world, double half_size_m,
                       const AlsParams& params, std::uint64_t seed);

struct AlsSummary {
  std::size_t pulses = 0;
  std::size_t points = 0;
  std::size_t last_returns = 0;  ///< second returns of two-return pulses
  std::size_t ground_points = 0;
  double area_m2 = 0.0;
  std::uintmax_t file_bytes = 0;
};

/// The plot (the scene's layout square) scanned from the air, written as LAS 1.4 in the
/// simulation's projected CRS (with its WKT), 1 mm resolution, return numbers and classes.
AlsSummary writeAls(const Simulation& simulation, const std::filesystem::path& path,
                    const AlsParams& params);

}  // namespace taiga::sim
