#include "taiga/eval/evaluate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "taiga/core/errors.hpp"
#include "taiga/core/percentile.hpp"

namespace taiga::eval {
namespace {

/// The --t-offset (added to the estimate's stamps, as evo's) that would make the stamps match:
/// the start difference when the spans do not overlap, then the median gap from each estimate
/// stamp to the reference stamp before it or to the one after it, whichever median is smaller
/// (e.g. half a scan when one is stamped at the scan's start and the other at its end; at
/// exactly half a period both match, and the one before is taken).
double suggestedTimeOffset(const Trajectory& est, const Trajectory& ref) {
  const bool overlap = est.startTime() <= ref.endTime() && ref.startTime() <= est.endTime();
  const double shift_s = overlap ? 0.0 : ref.startTime() - est.startTime();
  std::vector<double> ref_s;
  for (const StampedPose& p : ref.poses()) ref_s.push_back(p.t_s);
  std::vector<double> to_before_s, to_after_s;
  for (const StampedPose& p : est.poses()) {
    const double t_s = p.t_s + shift_s;
    const auto after = std::lower_bound(ref_s.begin(), ref_s.end(), t_s);
    if (after != ref_s.end()) to_after_s.push_back(*after - t_s);
    if (after != ref_s.begin()) to_before_s.push_back(*(after - 1) - t_s);
  }
  if (to_before_s.empty()) return shift_s + percentile(to_after_s, 50.0);
  if (to_after_s.empty()) return shift_s + percentile(to_before_s, 50.0);
  const double before_s = percentile(to_before_s, 50.0), after_s = percentile(to_after_s, 50.0);
  return shift_s + (std::abs(before_s) <= std::abs(after_s) ? before_s : after_s);
}

}  // namespace

EvalResult evaluate(const Trajectory& est, const Trajectory& ref, const EvalOptions& options) {
  EvalResult r;
  r.est_count = est.size();
  r.ref_count = ref.size();
  r.pairs = associate(est, ref, options.association);
  if (r.pairs.size() == 0 && (est.empty() || ref.empty()))
    throw InputError(fmt::format("nothing to evaluate: the estimate has {} poses, the reference {}",
                                 est.size(), ref.size()));
  if (r.pairs.size() == 0)
    throw InputError(fmt::format(
        "no matching time stamps between the estimate ({} poses, {:.3f} .. {:.3f} s) and the "
        "reference ({} poses, {:.3f} .. {:.3f} s) with --t-max-diff {} s and --t-offset {} s; "
        "--t-offset {:.6f} would make them match (taiga's trajectories are stamped at the scan's "
        "end)",
        est.size(), est.startTime(), est.endTime(), ref.size(), ref.startTime(), ref.endTime(),
        options.association.t_max_diff_s, options.association.t_offset_s,
        suggestedTimeOffset(est, ref)));
  r.alignment = options.alignment;
  r.transform = computeAlignment(r.pairs.est, r.pairs.ref, options.alignment);
  r.est_aligned = applyAlignment(r.pairs.est, r.transform);
  r.ape = computeApe(r.est_aligned, r.pairs.ref, options.rotation);
  r.rpe_frames = computeRpe(r.est_aligned, r.pairs.ref,
                            {static_cast<double>(options.rpe_delta_frames), DeltaUnit::kFrames});
  if (options.rpe_delta_m)
    r.rpe_metres =
        computeRpe(r.est_aligned, r.pairs.ref, {*options.rpe_delta_m, DeltaUnit::kMetres});
  r.kitti = computeKittiErrors(r.est_aligned, r.pairs.ref);
  r.drift = computeDrift(r.pairs.est, r.pairs.ref);
  r.distance = computeDistanceDistribution(r.pairs.est, r.pairs.ref, options.distance_bin_m);
  return r;
}

}  // namespace taiga::eval
