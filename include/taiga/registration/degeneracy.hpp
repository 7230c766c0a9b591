#pragma once
// Checks that decide whether an input can constrain all six degrees of freedom.

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>

namespace taiga::registration {

/// Smallest over largest eigenvalue of the points' covariance: 0 for points on one plane (or
/// line), about 1 for a blob. 0 for fewer than 3 points.
double planarityRatio(std::span<const Eigen::Vector3d> points);

/// A reason string when `points` (named `what`, e.g. "source") cannot be registered: empty,
/// containing non-finite points, fewer than `min_points` points, or planar (planarityRatio below
/// `planar_ratio`). Empty optional otherwise.
std::optional<std::string> inputProblem(std::span<const Eigen::Vector3d> points,
                                        const std::string& what, std::size_t min_points,
                                        double planar_ratio);

}  // namespace taiga::registration
