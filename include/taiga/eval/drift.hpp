#pragma once
// Metrics that need no full reference trajectory: end-point drift (thesis Tables 3 and 4) and
// the distribution of distances between two trajectories that should stay a bounded distance
// apart (thesis Fig. 19, e.g. two rigidly linked parts of a harvester).

#include <cstddef>
#include <vector>

#include "taiga/core/trajectory.hpp"

namespace taiga::eval {

/// End-point drift. The estimate is aligned on its first pose (as --align origin, whatever
/// alignment the other metrics use), so drift is the error accumulated from start to end:
///   drift_vector = p_est,last - p_ref,last after the origin alignment,
///   drift_percent = |drift_vector| / reference path length x 100,
/// with the path length summed over the associated reference positions.
/// `heading_aligned_drift_vector_m`: the same end-point error with the first pose aligned in
/// position and heading only (the turn about the vertical between the first poses' headings,
/// their x axes projected on the horizontal), for estimates whose z axis is gravity's, as
/// taiga's: an error in the first pose's roll and pitch then does not turn into a drift growing
/// with the distance from the start (0.5 deg: 0.9 m at 100 m), while a tilted world frame still
/// does.
/// `path_length_ratio`: the estimate's path length over the reference's, both summed over the
/// associated poses at which the reference has moved at least kPathStep_m since the previous one
/// (so that pose noise, which lengthens a path of short steps, stays out). Unlike a Sim(3) scale,
/// which an open trajectory's heading drift also moves, it measures whether the estimate's
/// steps are too short or too long: a loop closure cannot change it (bench/BENCHMARK.md,
/// "Session 66").
struct DriftResult {
  static constexpr double kPathStep_m = 1.0;
  Eigen::Vector3d drift_vector_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d heading_aligned_drift_vector_m = Eigen::Vector3d::Zero();
  double drift_m = 0.0;
  double reference_path_length_m = 0.0;
  double drift_percent = 0.0;  ///< 0 when the reference path length is 0
  double path_length_ratio = 0.0;  ///< 0 when the reference never moves kPathStep_m
};

DriftResult computeDrift(const std::vector<StampedPose>& est, const std::vector<StampedPose>& ref);

/// Distances d_i = |p_a,i - p_b,i| between associated positions, unaligned (both trajectories
/// in the same frame), and their histogram: bin k counts the d with floor(d / bin_width) == k,
/// i.e. k w <= d < (k + 1) w up to rounding; bins run from the minimum's bin to the maximum's.
struct DistanceDistribution {
  std::vector<double> distances_m;
  double bin_width_m = 0.1;
  double first_bin_start_m = 0.0;  ///< lower edge of counts[0]
  std::vector<std::size_t> counts;
  double mean_m = 0.0, std_m = 0.0, min_m = 0.0, max_m = 0.0;  ///< std: population (ddof 0)
};

/// InputError when bin_width_m is not positive.
DistanceDistribution computeDistanceDistribution(const std::vector<StampedPose>& a,
                                                 const std::vector<StampedPose>& b,
                                                 double bin_width_m = 0.1);

}  // namespace taiga::eval
