#pragma once
// Time association of an estimated and a reference trajectory, as evo's
// sync.associate_trajectories (evo_ape/evo_rpe --t_max_diff, --t_offset).
//
// Let `short` be the trajectory with fewer poses (the estimate when both have as many) and `long`
// the other. (1) For every pose of `short`, in order, take the pose of `long` whose stamp is
// nearest (the first one on a tie) and keep it when |t_long - t_short| <= t_max_diff_s; (2) for
// every kept pose of `long`, take the nearest pose of `short` in the same way. The two kept lists
// are the associated pairs, in order. t_offset_s is added to the estimate's stamps before
// comparing (the pairs keep the original stamps). A pose can appear in more than one pair when
// the tolerance is larger than half the spacing of the stamps, exactly as in evo.

#include <cstddef>
#include <vector>

#include "taiga/core/trajectory.hpp"

namespace taiga::eval {

struct AssociationOptions {
  double t_max_diff_s = 0.01;  ///< largest accepted |t_est + t_offset_s - t_ref|, s (evo default)
  double t_offset_s = 0.0;     ///< added to the estimate's stamps before matching, s
};

/// Associated pairs: est[i] and ref[i] belong together. Empty when nothing matched.
struct AssociatedPoses {
  std::vector<StampedPose> est;
  std::vector<StampedPose> ref;
  std::size_t size() const { return est.size(); }
};

AssociatedPoses associate(const Trajectory& est, const Trajectory& ref,
                          const AssociationOptions& options = {});

/// Index of the stamp in `stamps_shifted` (non-decreasing) nearest to t_s, the first one on a tie
/// (numpy.argmin of |stamps_shifted - t_s|). `stamps_shifted` must not be empty.
std::size_t nearestStampIndex(const std::vector<double>& stamps_shifted, double t_s);

}  // namespace taiga::eval
