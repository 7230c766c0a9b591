#pragma once
// The circle that circle_fit.cpp and beam_circle_fit.cpp fit, how its inliers spread around it,
// and its sigmas.

#include <Eigen/Core>
#include <span>
#include <vector>

#include "taiga/trees/circle_fit.hpp"

namespace taiga::trees {

/// A circle in the horizontal plane of a stem section, in the points' frame.
struct Circle {
  Eigen::Vector2d center_m;
  double radius_m = 0.0;
};

/// Angular coverage of the points with a positive weight around `center_m`, in 10 deg sectors.
double arcCoverageDeg(std::span<const Eigen::Vector2d> points_m, const std::vector<double>& weights,
                      const Eigen::Vector2d& center_m);

/// Share of the points with a positive weight in the densest 30 deg around `center_m`.
double densestShare(std::span<const Eigen::Vector2d> points_m, const std::vector<double>& weights,
                    const Eigen::Vector2d& center_m);

/// Sets `fit`'s sigma_radius_m and sigma_center_m (the larger axis of the centre's ellipse) from
/// the covariance of (cx, cy, r), and its arc_deg and densest_share from the points with a
/// positive weight around its centre.
void describeFit(CircleFit& fit, std::span<const Eigen::Vector2d> points_m,
                 const std::vector<double>& weights, const Eigen::Matrix3d& covariance);

}  // namespace taiga::trees
