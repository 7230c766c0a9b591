#pragma once
// Map sharpness on simulated data (issue 7, item 5): how far the map's points lie from the true
// scene surfaces, so that map quality is a number rather than a picture.
//
// The map is in the odometry's world frame, which differs from the simulator's by the first pose
// (and, without loop closure, by the drift). The points are moved into the truth frame with the
// same alignment the ATE uses (evaluate(): Umeyama SE(3) of the trajectory's positions onto the
// ground truth, `--align`), p_ref = s R p_est + t, so that the score measures the map's internal
// consistency (blur, doubled stems, bent ground) and not where the odometry put its origin. A
// map that is sharp in itself but drifted still scores worse than a consistent one, because one
// rigid transform cannot fit both ends.
//
// Each point's distance to the nearest surface is capped at cap_m (an outlier counts as cap_m,
// and the fraction beyond it is reported), then summarized: RMS, mean, median, p95. Large maps
// are scored on an evenly spaced subsample of at most max_points points.

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <vector>

#include "taiga/eval/alignment.hpp"

namespace taiga::eval {

struct MapSharpnessOptions {
  double cap_m = 1.0;               ///< distances are capped here, m
  std::size_t max_points = 200000;  ///< subsample size for large maps
};

struct MapSharpness {
  std::size_t map_points = 0;     ///< points in the map
  std::size_t points_scored = 0;  ///< the subsample
  double cap_m = 1.0;
  double rms_m = 0.0, mean_m = 0.0, median_m = 0.0, p95_m = 0.0;  ///< of the capped distances
  double fraction_beyond_cap = 0.0;
  AlignmentTransform transform;  ///< est (map) frame -> truth frame
};

/// Unsigned distance from a point in the truth frame to the nearest true surface, or max_m when
/// nothing is closer (sim::Scene::distanceToSurface). Called from one thread.
using SurfaceDistance = std::function<double(const Eigen::Vector3d& p_ref, double max_m)>;

/// Scores `points_est` (already subsampled if need be; `map_points` is the map's full size)
/// after moving them with `transform`. InputError when there are no points.
MapSharpness computeMapSharpness(const std::vector<Eigen::Vector3d>& points_est,
                                 std::size_t map_points, const AlignmentTransform& transform,
                                 const SurfaceDistance& distance,
                                 const MapSharpnessOptions& options = {});

}  // namespace taiga::eval
