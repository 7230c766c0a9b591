#include "taiga/sim/terrain.hpp"

#include <cmath>
#include <numbers>

#include "taiga/sim/random.hpp"

namespace taiga::sim {
namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}  // namespace

Terrain::Terrain(const ForestParams& params, std::uint64_t seed) {
  Rng rng(streamSeed(seed, "terrain"));
  const double slope_azimuth = rng.uniform(0.0, kTwoPi);
  slope_ = params.terrain_slope * Eigen::Vector2d(std::cos(slope_azimuth), std::sin(slope_azimuth));
  for (Wave& w : macro_) {
    const double wavelength_m = rng.uniform(30.0, 90.0);
    const double azimuth = rng.uniform(0.0, kTwoPi);
    w.k = kTwoPi / wavelength_m * Eigen::Vector2d(std::cos(azimuth), std::sin(azimuth));
    w.amplitude_m = params.terrain_undulation_m * rng.uniform(0.25, 0.5);
    w.phase_rad = rng.uniform(0.0, kTwoPi);
  }
  for (Wave& w : micro_) {
    const double wavelength_m = rng.uniform(1.2, 6.0);
    const double azimuth = rng.uniform(0.0, kTwoPi);
    w.k = kTwoPi / wavelength_m * Eigen::Vector2d(std::cos(azimuth), std::sin(azimuth));
    w.amplitude_m = params.micro_relief_m * rng.uniform(0.15, 0.35);
    w.phase_rad = rng.uniform(0.0, kTwoPi);
  }
}

double Terrain::smoothHeight(double x_m, double y_m, Eigen::Vector2d* gradient,
                             Eigen::Matrix2d* hessian) const {
  const Eigen::Vector2d p(x_m, y_m);
  double h = slope_.dot(p);
  if (gradient) *gradient = slope_;
  if (hessian) hessian->setZero();
  for (const Wave& w : macro_) {
    const double arg = w.k.dot(p) + w.phase_rad;
    h += w.amplitude_m * std::sin(arg);
    if (gradient) *gradient += w.amplitude_m * std::cos(arg) * w.k;
    if (hessian) *hessian -= w.amplitude_m * std::sin(arg) * w.k * w.k.transpose();
  }
  return h;
}

double Terrain::height(double x_m, double y_m) const {
  const Eigen::Vector2d p(x_m, y_m);
  double h = smoothHeight(x_m, y_m);
  for (const Wave& w : micro_) {
    // Rectified sines make rounded hummocks rather than a washboard.
    h += w.amplitude_m * (std::abs(std::sin(w.k.dot(p) + w.phase_rad)) - 0.5);
  }
  return h;
}

}  // namespace taiga::sim
