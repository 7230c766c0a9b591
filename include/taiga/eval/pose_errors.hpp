#pragma once
// Absolute and relative pose errors, with evo's definitions (evo/core/metrics.py).
//
// APE (evo_ape): on associated, aligned pairs (P_i estimate, Q_i reference),
//   translation error e_i = |p_i - q_i| (m)                      evo_ape -r trans_part (default)
//   rotation error   a_i = angle(P_i^-1 Q_i) in degrees           evo_ape -r angle_deg
// RPE (evo_rpe): over pairs (i, j) of associated indices,
//   E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j),  e = |trans(E)| (m),  a = angle(rot(E)) (deg).
// The pairs are evo's "consecutive pairs" (not --all_pairs), chosen on the ESTIMATE's poses:
//   delta in frames  (--delta N --delta_unit f): (0, N), (N, 2N), (2N, 3N), ...
//   delta in metres  (--delta D --delta_unit m): walk the estimate accumulating the distance
//     between successive positions (starting with 0 at index 0); each index where the sum reaches
//     D is kept and the sum restarts at 0; the pairs join successive kept indices (so the first
//     pair starts at the first index D metres along, not at index 0, as in evo).
// Angles come from the rotation's axis-angle magnitude, in [0, 180] degrees.

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "taiga/core/trajectory.hpp"
#include "taiga/eval/statistics.hpp"

namespace taiga::eval {

struct ApeResult {
  std::vector<double> translation_error_m;  ///< one per pair
  ErrorStatistics translation_m;
  Eigen::Vector3d rmse_per_axis_m = Eigen::Vector3d::Zero();  ///< RMSE of x, y, z differences
  std::vector<double> rotation_error_deg;                     ///< empty unless requested
  std::optional<ErrorStatistics> rotation_deg;
};

/// APE of `est` (already aligned) against `ref`; pairs of equal size.
ApeResult computeApe(const std::vector<StampedPose>& est, const std::vector<StampedPose>& ref,
                     bool with_rotation);

enum class DeltaUnit { kFrames, kMetres };

struct RpeOptions {
  double delta = 1.0;  ///< frames (a positive integer) or metres of path (positive)
  DeltaUnit unit = DeltaUnit::kFrames;
};

struct RpeResult {
  RpeOptions options;
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  ///< indices into the associated poses
  std::vector<double> translation_error_m;                 ///< one per pair
  ErrorStatistics translation_m;
  std::vector<double> rotation_error_deg;  ///< one per pair (always computed, cheap)
  ErrorStatistics rotation_deg;
};

/// Index pairs as evo's filters.filter_pairs_by_index / filter_pairs_by_path (consecutive pairs).
std::vector<std::pair<std::size_t, std::size_t>> rpePairs(const std::vector<StampedPose>& est,
                                                          const RpeOptions& options);

/// RPE; InputError when the delta is not positive (or not an integer in frames). An empty
/// result (no pairs) means the trajectory is shorter than the delta.
RpeResult computeRpe(const std::vector<StampedPose>& est, const std::vector<StampedPose>& ref,
                     const RpeOptions& options);

/// Rotation angle of R in degrees, in [0, 180].
double rotationAngleDeg(const lie::SO3& R);

}  // namespace taiga::eval
