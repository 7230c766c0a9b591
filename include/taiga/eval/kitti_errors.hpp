#pragma once
// KITTI odometry benchmark errors, as the devkit's evaluate_odometry.cpp (calcSequenceErrors):
// from every 10th associated pose (first_frame = 0, 10, 20, ...) and for every segment length
// L in 100, 200, ..., 800 m, the last frame is the first index whose distance along the
// REFERENCE path exceeds that of first_frame by more than L (segments that run past the end are
// skipped). With the relative motions dQ = Q_first^-1 Q_last and dP = P_first^-1 P_last, the
// error pose is E = dP^-1 dQ; the segment's errors are |trans(E)| / L and angle(rot(E)) / L.
// The results are the means over all segments: translational error in percent (x 100) and
// rotational error in degrees per 100 m (rad/m x 180/pi x 100). The devkit computes in float;
// taiga computes in double, so the last printed digits can differ.

#include <cstddef>
#include <optional>
#include <vector>

#include "taiga/core/trajectory.hpp"

namespace taiga::eval {

struct KittiSegmentError {
  std::size_t first = 0, last = 0;        ///< associated indices
  double length_m = 0.0;                  ///< the nominal segment length L
  double translation_error_ratio = 0.0;   ///< |trans(E)| / L (m/m)
  double rotation_error_rad_per_m = 0.0;  ///< angle(rot(E)) / L
};

struct KittiResult {
  std::vector<KittiSegmentError> segments;
  double translation_error_percent = 0.0;    ///< mean translation ratio x 100
  double rotation_error_deg_per_100m = 0.0;  ///< mean rotation rate x 180/pi x 100
};

struct KittiOptions {
  std::vector<double> lengths_m{100, 200, 300, 400, 500, 600, 700, 800};
  std::size_t step_frames = 10;
};

/// Empty (nullopt) when no segment fits, i.e. the reference path is not longer than the
/// shortest segment length.
std::optional<KittiResult> computeKittiErrors(const std::vector<StampedPose>& est,
                                              const std::vector<StampedPose>& ref,
                                              const KittiOptions& options = {});

}  // namespace taiga::eval
