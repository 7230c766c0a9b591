#include "taiga/eval/pose_errors.hpp"

#include <fmt/format.h>

#include <cassert>
#include <cmath>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::eval {

double rotationAngleDeg(const lie::SO3& R) { return R.angle() * kDegPerRad; }

ApeResult computeApe(const std::vector<StampedPose>& est, const std::vector<StampedPose>& ref,
                     bool with_rotation) {
  assert(est.size() == ref.size());
  ApeResult result;
  result.translation_error_m.reserve(est.size());
  Eigen::Vector3d sum_squares = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < est.size(); ++i) {
    const Eigen::Vector3d d = est[i].pose.translation() - ref[i].pose.translation();
    result.translation_error_m.push_back(d.norm());
    sum_squares += d.cwiseProduct(d);
    if (with_rotation) {
      const lie::SO3 error = est[i].pose.rotation().inverse() * ref[i].pose.rotation();
      result.rotation_error_deg.push_back(rotationAngleDeg(error));
    }
  }
  result.translation_m = computeStatistics(result.translation_error_m);
  if (!est.empty())
    result.rmse_per_axis_m = (sum_squares / static_cast<double>(est.size())).cwiseSqrt();
  if (with_rotation) result.rotation_deg = computeStatistics(result.rotation_error_deg);
  return result;
}

std::vector<std::pair<std::size_t, std::size_t>> rpePairs(const std::vector<StampedPose>& est,
                                                          const RpeOptions& options) {
  std::vector<std::size_t> ids;
  if (options.unit == DeltaUnit::kFrames) {
    const auto step = static_cast<std::size_t>(options.delta);
    for (std::size_t i = 0; i < est.size(); i += step) ids.push_back(i);
  } else {
    double path_m = 0.0;
    for (std::size_t i = 0; i < est.size(); ++i) {
      if (i > 0) path_m += (est[i].pose.translation() - est[i - 1].pose.translation()).norm();
      if (path_m >= options.delta) {
        ids.push_back(i);
        path_m = 0.0;
      }
    }
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

RpeResult computeRpe(const std::vector<StampedPose>& est, const std::vector<StampedPose>& ref,
                     const RpeOptions& options) {
  assert(est.size() == ref.size());
  if (!(options.delta > 0.0) || !std::isfinite(options.delta))
    throw InputError(fmt::format("RPE delta {} is not a positive number", options.delta));
  if (options.unit == DeltaUnit::kFrames && std::floor(options.delta) != options.delta)
    throw InputError(fmt::format("RPE delta {} frames is not a whole number", options.delta));
  RpeResult result;
  result.options = options;
  result.pairs = rpePairs(est, options);
  for (const auto& [i, j] : result.pairs) {
    const lie::SE3 Q_rel = ref[i].pose.inverse() * ref[j].pose;
    const lie::SE3 P_rel = est[i].pose.inverse() * est[j].pose;
    const lie::SE3 E = Q_rel.inverse() * P_rel;
    result.translation_error_m.push_back(E.translation().norm());
    result.rotation_error_deg.push_back(rotationAngleDeg(E.rotation()));
  }
  result.translation_m = computeStatistics(result.translation_error_m);
  result.rotation_deg = computeStatistics(result.rotation_error_deg);
  return result;
}

}  // namespace taiga::eval
