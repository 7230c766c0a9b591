#include "taiga/eval/association.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>

#include "taiga/core/errors.hpp"

namespace taiga::eval {
namespace {

// Indices into `search` (stamps shifted by `offset_s`) matched to each stamp of `query`, as evo's
// sync.matching_time_indices.
std::vector<std::size_t> matchingIndices(const std::vector<double>& query,
                                         const std::vector<double>& search, double max_diff_s,
                                         double offset_s) {
  std::vector<double> shifted(search.size());
  for (std::size_t i = 0; i < search.size(); ++i) shifted[i] = search[i] + offset_s;
  std::vector<std::size_t> indices;
  if (shifted.empty()) return indices;
  for (const double t_s : query) {
    const std::size_t k = nearestStampIndex(shifted, t_s);
    if (std::abs(shifted[k] - t_s) <= max_diff_s) indices.push_back(k);
  }
  return indices;
}

std::vector<double> stampsOf(const std::vector<StampedPose>& poses) {
  std::vector<double> stamps;
  stamps.reserve(poses.size());
  for (const StampedPose& p : poses) stamps.push_back(p.t_s);
  return stamps;
}

std::vector<StampedPose> pick(const std::vector<StampedPose>& poses,
                              const std::vector<std::size_t>& indices) {
  std::vector<StampedPose> picked;
  picked.reserve(indices.size());
  for (const std::size_t i : indices) picked.push_back(poses[i]);
  return picked;
}

}  // namespace

std::size_t nearestStampIndex(const std::vector<double>& stamps_shifted, double t_s) {
  assert(!stamps_shifted.empty());
  const auto it = std::lower_bound(stamps_shifted.begin(), stamps_shifted.end(), t_s);
  const auto upper = static_cast<std::size_t>(it - stamps_shifted.begin());
  if (upper == 0) return 0;
  std::size_t lower = upper - 1;
  while (lower > 0 && stamps_shifted[lower - 1] == stamps_shifted[lower]) --lower;
  if (upper == stamps_shifted.size()) return lower;
  return std::abs(stamps_shifted[lower] - t_s) <= std::abs(stamps_shifted[upper] - t_s) ? lower
                                                                                        : upper;
}

AssociatedPoses associate(const Trajectory& est, const Trajectory& ref,
                          const AssociationOptions& options) {
  // evo_ape calls associate_trajectories(traj_ref, traj_est, max_diff, offset): the estimate is
  // the second trajectory, and it is the longer one only when it has strictly more poses.
  const bool est_longer = est.size() > ref.size();
  const std::vector<StampedPose>& long_poses = est_longer ? est.poses() : ref.poses();
  const std::vector<StampedPose>& short_poses = est_longer ? ref.poses() : est.poses();
  const double offset_long_s = est_longer ? options.t_offset_s : -options.t_offset_s;

  const std::vector<std::size_t> long_ids = matchingIndices(
      stampsOf(short_poses), stampsOf(long_poses), options.t_max_diff_s, offset_long_s);
  const std::vector<StampedPose> long_kept = pick(long_poses, long_ids);
  const std::vector<std::size_t> short_ids = matchingIndices(
      stampsOf(long_kept), stampsOf(short_poses), options.t_max_diff_s, -offset_long_s);
  const std::vector<StampedPose> short_kept = pick(short_poses, short_ids);

  AssociatedPoses pairs;
  if (short_kept.size() != long_kept.size()) {
    // Every kept long stamp has a short stamp within the tolerance (the one that chose it), so
    // the reverse pass keeps all of them, unless rounding puts a difference exactly on the edge.
    throw InputError(fmt::format(
        "time association is ambiguous: a stamp difference lies on the tolerance {} s up to "
        "rounding; choose a slightly different --t-max-diff",
        options.t_max_diff_s));
  }
  pairs.est = est_longer ? long_kept : short_kept;
  pairs.ref = est_longer ? short_kept : long_kept;
  return pairs;
}

}  // namespace taiga::eval
