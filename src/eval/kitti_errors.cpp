#include "taiga/eval/kitti_errors.hpp"

#include <cassert>

#include "taiga/core/angles.hpp"

namespace taiga::eval {

std::optional<KittiResult> computeKittiErrors(const std::vector<StampedPose>& est,
                                              const std::vector<StampedPose>& ref,
                                              const KittiOptions& options) {
  assert(est.size() == ref.size());
  std::vector<double> distance_m(ref.size(), 0.0);
  for (std::size_t i = 1; i < ref.size(); ++i)
    distance_m[i] =
        distance_m[i - 1] + (ref[i].pose.translation() - ref[i - 1].pose.translation()).norm();

  KittiResult result;
  const std::size_t step = options.step_frames > 0 ? options.step_frames : 1;
  for (std::size_t first = 0; first < ref.size(); first += step) {
    for (const double length_m : options.lengths_m) {
      std::size_t last = first;
      while (last < ref.size() && !(distance_m[last] > distance_m[first] + length_m)) ++last;
      if (last == ref.size()) continue;
      const lie::SE3 dQ = ref[first].pose.inverse() * ref[last].pose;
      const lie::SE3 dP = est[first].pose.inverse() * est[last].pose;
      const lie::SE3 E = dP.inverse() * dQ;
      result.segments.push_back({first, last, length_m, E.translation().norm() / length_m,
                                 E.rotation().angle() / length_m});
    }
  }
  if (result.segments.empty()) return std::nullopt;
  double sum_t = 0.0, sum_r = 0.0;
  for (const KittiSegmentError& s : result.segments) {
    sum_t += s.translation_error_ratio;
    sum_r += s.rotation_error_rad_per_m;
  }
  const double n = static_cast<double>(result.segments.size());
  result.translation_error_percent = sum_t / n * 100.0;
  result.rotation_error_deg_per_100m = sum_r / n * kDegPerRad * 100.0;
  return result;
}

}  // namespace taiga::eval
