#include "taiga/georef/association.hpp"

#include <algorithm>
#include <cassert>

namespace taiga::georef {

Association associateFixes(const Trajectory& trajectory_world_body,
                           const std::vector<LocalFix>& fixes, const AssociationOptions& options) {
  assert(!trajectory_world_body.empty());
  const std::vector<StampedPose>& poses = trajectory_world_body.poses();
  Association association;
  for (const LocalFix& fix : fixes) {
    if (!trajectory_world_body.covers(fix.t_s)) {
      ++association.outside_span;
      continue;
    }
    // The first pose later than the fix; the fix lies in [before, after).
    auto after = std::upper_bound(poses.begin(), poses.end(), fix.t_s,
                                  [](double t, const StampedPose& pose) { return t < pose.t_s; });
    // covers() puts the fix at or after the first pose, so `after` is not the first pose.
    const StampedPose& before = *(after - 1);
    lie::SE3 T_world_body;
    if (before.t_s == fix.t_s) {
      T_world_body = before.pose;  // exactly at a pose: no gap to check
    } else {
      if (after->t_s - before.t_s > options.max_gap_s) {
        ++association.in_gap;
        continue;
      }
      const double s = (fix.t_s - before.t_s) / (after->t_s - before.t_s);
      T_world_body = lie::interpolate(before.pose, after->pose, s);
    }
    association.pairs.push_back({fix, T_world_body, T_world_body * options.p_body_antenna});
  }
  return association;
}

}  // namespace taiga::georef
