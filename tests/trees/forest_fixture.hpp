#pragma once
// Synthetic forest clouds for the trees tests: sloped ground, stems (optionally leaning, seen
// from one side), a boulder, a log and a bush, with Gaussian noise. Deterministic.

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace taiga::test {

struct SyntheticStem {
  Eigen::Vector2d base_xy;
  double dbh_m;
  double lean_x = 0.0;  ///< d(x)/dh of the axis
  double min_angle_rad = -std::numbers::pi, max_angle_rad = std::numbers::pi;  ///< visible arc
  double taper = 0.0;        ///< d(radius)/dh, the radius being dbh_m / 2 at 1.3 m
  int points_per_ring = 60;  ///< every 2 cm of height
};

inline double groundZ(double x, double y) { return 0.3 * x + 0.1 * y; }  // a 30 % slope

inline std::vector<Eigen::Vector3d> syntheticForest(const std::vector<SyntheticStem>& stems,
                                                    double noise_m, unsigned seed = 1,
                                                    bool clutter = true) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (double x = -10; x <= 10; x += 0.1)
    for (double y = -10; y <= 10; y += 0.1) points.emplace_back(x, y, groundZ(x, y) + noise(rng));
  for (const SyntheticStem& s : stems) {
    const double ground = groundZ(s.base_xy.x(), s.base_xy.y());
    for (double h = 0.0; h < 6.0; h += 0.02)
      for (int k = 0; k < s.points_per_ring; ++k) {
        const double a = s.min_angle_rad + (s.max_angle_rad - s.min_angle_rad) * u(rng);
        const double r = 0.5 * s.dbh_m + s.taper * (h - 1.3) + noise(rng);
        points.emplace_back(s.base_xy.x() + s.lean_x * h + r * std::cos(a),
                            s.base_xy.y() + r * std::sin(a), ground + h);
      }
  }
  if (clutter) {
    // A boulder (1 m radius dome), a fallen log along y, a bush (a ball of foliage at 1.3 m).
    for (int i = 0; i < 4000; ++i) {
      const double a = 2 * std::numbers::pi * u(rng), e = 0.5 * std::numbers::pi * u(rng);
      points.emplace_back(6 + std::cos(a) * std::cos(e), -6 + std::sin(a) * std::cos(e),
                          groundZ(6, -6) + std::sin(e));
      const double log_y = -8 + 6 * u(rng);
      points.emplace_back(-6 + 0.25 * std::cos(a), log_y,
                          groundZ(-6, log_y) + 0.25 + 0.25 * std::sin(a));
      const Eigen::Vector3d bush = Eigen::Vector3d(u(rng), u(rng), u(rng)).array() - 0.5;
      points.push_back(Eigen::Vector3d(-3, 6, groundZ(-3, 6) + 1.3) + 1.2 * bush);
    }
  }
  return points;
}

}  // namespace taiga::test
