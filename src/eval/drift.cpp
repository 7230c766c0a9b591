#include "taiga/eval/drift.hpp"

#include <fmt/format.h>

#include <cassert>
#include <cmath>

#include <Eigen/Geometry>

#include "taiga/core/errors.hpp"
#include "taiga/eval/alignment.hpp"
#include "taiga/eval/statistics.hpp"

namespace taiga::eval {

namespace {
double pathLengthRatio(const std::vector<StampedPose>& est, const std::vector<StampedPose>& ref) {
  double est_m = 0.0, ref_m = 0.0;
  std::size_t last = 0;
  for (std::size_t i = 1; i < ref.size(); ++i) {
    const double step_m = (ref[i].pose.translation() - ref[last].pose.translation()).norm();
    if (step_m < DriftResult::kPathStep_m) continue;
    ref_m += step_m;
    est_m += (est[i].pose.translation() - est[last].pose.translation()).norm();
    last = i;
  }
  return ref_m > 0.0 ? est_m / ref_m : 0.0;
}
}  // namespace

DriftResult computeDrift(const std::vector<StampedPose>& est, const std::vector<StampedPose>& ref) {
  assert(est.size() == ref.size());
  DriftResult result;
  if (est.empty()) return result;
  const AlignmentTransform origin = computeAlignment(est, ref, Alignment::kOrigin);
  const Eigen::Vector3d p_est_last = origin.T_ref_est * est.back().pose.translation();
  result.drift_vector_m = p_est_last - ref.back().pose.translation();
  result.drift_m = result.drift_vector_m.norm();
  // Heading only: the turn about z between the first poses' headings (their x axes projected
  // on the horizontal), whatever their roll and pitch.
  const auto headingRad = [](const StampedPose& p) {
    const Eigen::Matrix3d R = p.pose.rotation().matrix();
    return std::atan2(R(1, 0), R(0, 0));
  };
  const Eigen::Matrix3d R_heading =
      Eigen::AngleAxisd(headingRad(ref.front()) - headingRad(est.front()),
                        Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  result.heading_aligned_drift_vector_m =
      R_heading * (est.back().pose.translation() - est.front().pose.translation()) -
      (ref.back().pose.translation() - ref.front().pose.translation());
  for (std::size_t i = 1; i < ref.size(); ++i)
    result.reference_path_length_m +=
        (ref[i].pose.translation() - ref[i - 1].pose.translation()).norm();
  if (result.reference_path_length_m > 0.0)
    result.drift_percent = result.drift_m / result.reference_path_length_m * 100.0;
  result.path_length_ratio = pathLengthRatio(est, ref);
  return result;
}

DistanceDistribution computeDistanceDistribution(const std::vector<StampedPose>& a,
                                                 const std::vector<StampedPose>& b,
                                                 double bin_width_m) {
  assert(a.size() == b.size());
  if (!(bin_width_m > 0.0) || !std::isfinite(bin_width_m))
    throw InputError(fmt::format("histogram bin width {} m is not a positive number", bin_width_m));
  DistanceDistribution result;
  result.bin_width_m = bin_width_m;
  for (std::size_t i = 0; i < a.size(); ++i)
    result.distances_m.push_back((a[i].pose.translation() - b[i].pose.translation()).norm());
  if (result.distances_m.empty()) return result;
  const ErrorStatistics s = computeStatistics(result.distances_m);
  result.mean_m = s.mean;
  result.std_m = s.std;
  result.min_m = s.min;
  result.max_m = s.max;
  const auto first_bin = static_cast<long long>(std::floor(s.min / bin_width_m));
  const auto last_bin = static_cast<long long>(std::floor(s.max / bin_width_m));
  constexpr long long kMaxBins = 100000;
  if (last_bin - first_bin + 1 > kMaxBins)
    throw InputError(fmt::format(
        "the distances span {} m to {} m: more than {} bins of {} m; choose a wider bin "
        "(--distance-bin-m)",
        s.min, s.max, kMaxBins, bin_width_m));
  result.first_bin_start_m = static_cast<double>(first_bin) * bin_width_m;
  result.counts.assign(static_cast<std::size_t>(last_bin - first_bin + 1), 0);
  for (const double d : result.distances_m)
    ++result.counts[static_cast<std::size_t>(static_cast<long long>(std::floor(d / bin_width_m)) -
                                             first_bin)];
  return result;
}

}  // namespace taiga::eval
