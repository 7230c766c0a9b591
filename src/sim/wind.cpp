#include "taiga/sim/wind.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "taiga/sim/random.hpp"
#include "taiga/sim/scene.hpp"

namespace taiga::sim {
namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kSwayFoot_m = 2.0;       ///< below this height above the ground nothing sways
constexpr double kSwayReference_m = 20.0;  ///< height of unit gain
constexpr double kGustSpacing_m = 40.0;    ///< distance between gust fronts along the wind
}  // namespace

Wind::Wind(const ForestParams& params, std::uint64_t seed)
    : amplitude_m_(params.wind_sway_m), omega_radps_(kTwoPi / params.wind_period_s) {
  const double azimuth = kTwoPi * hashUniform(streamSeed(seed, "wind"), 0);
  direction_world_ = Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), 0.0);
}

bool Wind::sways(Material material) {
  return material == Material::kBark || material == Material::kBranch ||
         material == Material::kFoliage;
}

double Wind::gain(Material material, double height_above_ground_m) {
  double factor = 0.0;
  if (material == Material::kBark) factor = 1.0;
  if (material == Material::kBranch || material == Material::kFoliage) factor = 2.0;
  return factor * std::max(0.0, height_above_ground_m - kSwayFoot_m) /
         (kSwayReference_m - kSwayFoot_m);
}

Eigen::Vector3d Wind::displacement_m(const Eigen::Vector3d& p_world, double t_s) const {
  const double phi = kTwoPi * p_world.dot(direction_world_) / kGustSpacing_m;
  const double wt = omega_radps_ * t_s;
  const Eigen::Vector3d across(-direction_world_.y(), direction_world_.x(), 0.0);
  return amplitude_m_ *
         ((0.7 * std::sin(wt + phi) + 0.3 * std::sin(2.7 * wt + 1.7 * phi)) * direction_world_ +
          0.3 * std::sin(1.6 * wt + 2.3 * phi) * across);
}

}  // namespace taiga::sim
