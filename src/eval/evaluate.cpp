#include "taiga/eval/evaluate.hpp"

#include <fmt/format.h>

#include "taiga/core/errors.hpp"

namespace taiga::eval {

EvalResult evaluate(const Trajectory& est, const Trajectory& ref, const EvalOptions& options) {
  EvalResult r;
  r.est_count = est.size();
  r.ref_count = ref.size();
  r.pairs = associate(est, ref, options.association);
  if (r.pairs.size() == 0)
    throw InputError(fmt::format(
        "no matching time stamps between the estimate ({} poses) and the reference ({} poses) "
        "with --t-max-diff {} s and --t-offset {} s",
        est.size(), ref.size(), options.association.t_max_diff_s, options.association.t_offset_s));
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
