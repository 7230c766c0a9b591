#pragma once
// One evaluation of an estimated trajectory against a reference: association, alignment, then
// every metric (docs/evaluation.md lists each with the evo or KITTI command it matches).

#include <cstddef>
#include <optional>

#include "taiga/core/trajectory.hpp"
#include "taiga/eval/alignment.hpp"
#include "taiga/eval/association.hpp"
#include "taiga/eval/drift.hpp"
#include "taiga/eval/kitti_errors.hpp"
#include "taiga/eval/pose_errors.hpp"

namespace taiga::eval {

struct EvalOptions {
  AssociationOptions association;
  Alignment alignment = Alignment::kSe3;
  bool rotation = false;              ///< APE rotation part (degrees)
  std::size_t rpe_delta_frames = 1;   ///< evo_rpe --delta N --delta_unit f
  std::optional<double> rpe_delta_m;  ///< evo_rpe --delta D --delta_unit m, on request
  double distance_bin_m = 0.1;        ///< histogram bin of the distance distribution
};

struct EvalResult {
  std::size_t est_count = 0, ref_count = 0;  ///< poses in the files
  AssociatedPoses pairs;                     ///< the associated poses as read
  std::vector<StampedPose> est_aligned;      ///< pairs.est after the alignment
  Alignment alignment = Alignment::kSe3;
  AlignmentTransform transform;
  ApeResult ape;
  RpeResult rpe_frames;
  std::optional<RpeResult> rpe_metres;
  std::optional<KittiResult> kitti;  ///< empty when the path is shorter than 100 m
  DriftResult drift;
  DistanceDistribution distance;  ///< unaligned est-ref distances
};

/// Throws InputError when no stamps associate (naming the tolerance and offset) or when the
/// alignment is impossible; the caller adds the file names.
EvalResult evaluate(const Trajectory& est, const Trajectory& ref, const EvalOptions& options);

}  // namespace taiga::eval
