#pragma once
// The ground of a simulated forest: a smooth analytic height field (slope and long-wave relief,
// with exact gradient and Hessian, which the walking motion follows) plus short-wave micro-relief
// (hummocks and pits) that only the meshed ground surface carries.

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "taiga/sim/scenario.hpp"

namespace taiga::sim {

class Terrain {
 public:
  Terrain(const ForestParams& params, std::uint64_t seed);

  /// Smooth height z_world(x, y), m; optional exact gradient and Hessian.
  double smoothHeight(double x_m, double y_m, Eigen::Vector2d* gradient = nullptr,
                      Eigen::Matrix2d* hessian = nullptr) const;
  /// Ground surface height including the micro-relief, m (what the lidar sees).
  double height(double x_m, double y_m) const;

 private:
  struct Wave {
    Eigen::Vector2d k;  ///< wave vector, rad/m
    double amplitude_m;
    double phase_rad;
  };
  Eigen::Vector2d slope_;
  std::array<Wave, 4> macro_{};
  std::array<Wave, 8> micro_{};
};

}  // namespace taiga::sim
