#pragma once
// Wind in the simulated forest: stems, branches and foliage sway horizontally, so that the world
// the lidar sees moves a little between scans (docs/simulator.md, "Realism"). The ray casting
// stays on the still geometry; a return from a swaying surface is displaced by the sway at its
// firing time, which for a surface sampled by many beams is the surface moved.
//
//   d(p, t) = A g(p) [ w (0.7 sin(W t + phi) + 0.3 sin(2.7 W t + 1.7 phi))
//                      + w_perp 0.3 sin(1.6 W t + 2.3 phi) ],   phi = 2 pi (p . w) / 40 m,
//
// W = 2 pi / wind_period_s, w the wind direction (drawn from the seed), phi a gust front that
// travels downwind, and g(p) the gain: zero up to 2 m above the ground, growing linearly to 1 at
// 20 m (x2 for branches and foliage, x0 for the ground, rocks, logs and the machine).

#include <Eigen/Core>
#include <cstdint>

#include "taiga/sim/scenario.hpp"

namespace taiga::sim {

enum class Material : std::uint8_t;

class Wind {
 public:
  Wind(const ForestParams& params, std::uint64_t seed);

  bool calm() const { return amplitude_m_ <= 0.0; }
  /// Whether a surface of that material moves at all (bark, branches, foliage).
  static bool sways(Material material);
  /// Gain g of a surface of that material at that height above the ground (0: it stays).
  static double gain(Material material, double height_above_ground_m);
  /// Horizontal sway of a surface of gain 1 at p_world and motion time t, m.
  Eigen::Vector3d displacement_m(const Eigen::Vector3d& p_world, double t_s) const;

 private:
  double amplitude_m_;
  double omega_radps_;
  Eigen::Vector3d direction_world_;
};

}  // namespace taiga::sim
