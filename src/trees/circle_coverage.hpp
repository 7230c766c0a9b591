#pragma once
// How a fitted circle's inliers spread around it (circle_fit.cpp, beam_circle_fit.cpp).

#include <Eigen/Core>
#include <span>
#include <vector>

namespace taiga::trees {

/// Angular coverage of the points with a positive weight around `center_m`, in 10 deg sectors.
double arcCoverageDeg(std::span<const Eigen::Vector2d> points_m, const std::vector<double>& weights,
                      const Eigen::Vector2d& center_m);

/// Share of the points with a positive weight in the densest 30 deg around `center_m`.
double densestShare(std::span<const Eigen::Vector2d> points_m, const std::vector<double>& weights,
                    const Eigen::Vector2d& center_m);

}  // namespace taiga::trees
