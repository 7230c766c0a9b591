#pragma once
// A stem section's circle from lidar points whose beams are known (docs/trees.md, "Where the DBH
// error comes from"): errors in variables.
//
// Each point is a range measurement along its beam, with a range noise sigma_range that grows with
// distance and with the weakness of the return (on dark bark at 13 m it is as large as a thin
// stem's radius), and its sensor's placement is uncertain across the beam by sigma_across (the
// keyframe's placement, the beam's footprint, the bark). A point's residual is its Mahalanobis
// distance, under that covariance, to the nearest point of the circle's side that faces its
// sensor: e = ((p - q).v / sigma_range, (p - q).u / sigma_across) with v the beam, u across it,
// q on the visible half. A beam that meets the circle gives q near its near-side intersection (the
// along-beam residual); a beam that misses it or grazes it gives q at the silhouette and an
// across-beam residual, so a smaller circle that leaves a view's edge points off its beams pays for
// them (the along-beam residual alone scored them as nothing, and a crescent of noisy points made
// the circle 2-4 cm too small in radius).
//
// The radius of a far, noisy crescent is weakly determined, and a local fit stays near its start:
// so the fit first profiles the robust cost over radii from 0.6 to 2 times the start's (the
// centre fitted for each), then refines centre and radius from the best: Gauss-Newton on the
// scalar Mahalanobis norm m (the nearest point eliminated, gradient J^T e / m), Tukey's biweight on
// m (cut at 3) dropping clutter.
//
// The nearest point may slide along the surface, by more the nearer sigma_across comes to
// sigma_range; where they are alike the fit is the fit across the surface, with its small bias.
// The default sigma_across (1 cm) suits a map whose keyframes' views do not quite meet; for one
// sensor with exact beams pass less (CircleFitOptions::across_beam_sigma_m; BENCHMARK.md,
// "Session 58").

#include <Eigen/Core>
#include <optional>
#include <span>

#include "taiga/trees/circle_fit.hpp"

namespace taiga::trees {

/// The fit to `points_m` with `beams` (unit horizontal directions from the sensor towards each
/// point; a zero vector where unknown: that point's residual is across the surface, in units of
/// sigma_range). `range_sigma_m` is the points' range noise (1-sigma); the across-beam sigma is
/// `options.across_beam_sigma_m`. Nothing when fewer than 5 points keep a weight or the radius
/// leaves the options' range. `rms_m` is the scatter across the surface, as refineCircle's.
std::optional<CircleFit> fitCircleAlongBeams(std::span<const Eigen::Vector2d> points_m,
                                             std::span<const Eigen::Vector2d> beams,
                                             const Eigen::Vector2d& start_center_m,
                                             double start_radius_m, double range_sigma_m,
                                             const CircleFitOptions& options = {});

}  // namespace taiga::trees
