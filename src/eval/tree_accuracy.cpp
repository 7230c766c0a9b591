#include "taiga/eval/tree_accuracy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace taiga::eval {
namespace {

double pathDistance(const Eigen::Vector2d& p, const std::vector<Eigen::Vector3d>& path_m) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < path_m.size(); ++i) {
    const Eigen::Vector2d a = path_m[i].head<2>(), b = path_m[i + 1].head<2>();
    const Eigen::Vector2d ab = b - a;
    const double t =
        ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    best = std::min(best, (a + t * ab - p).norm());
  }
  if (path_m.size() == 1) best = (path_m[0].head<2>() - p).norm();
  return best;
}

std::size_t dbhClass(double dbh_m) {
  return static_cast<std::size_t>(std::clamp(std::floor(dbh_m / 0.1) - 1.0, 0.0, 3.0));
}

}  // namespace

TreeAccuracy evaluateTrees(const std::vector<trees::TreeRecord>& estimate,
                           const std::vector<trees::TreeRecord>& reference,
                           const AlignmentTransform& T,
                           const std::vector<Eigen::Vector3d>& reference_path_m,
                           const TreeAccuracyOptions& o) {
  TreeAccuracy a;
  a.options = o;
  // Estimated stems into the reference frame: p_ref = s R p_est + t (the breast-height point).
  std::vector<Eigen::Vector2d> est_xy(estimate.size());
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const double z = std::isnan(estimate[i].ground_z_m) ? 0.0 : estimate[i].ground_z_m + 1.3;
    const Eigen::Vector3d p(estimate[i].bh_xy_m.x(), estimate[i].bh_xy_m.y(), z);
    est_xy[i] = (T.scale * (T.T_ref_est.rotation() * p) + T.T_ref_est.translation()).head<2>();
  }

  // Closest pairs first, each tree at most once.
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < estimate.size(); ++i)
    for (std::size_t j = 0; j < reference.size(); ++j) {
      const double d = (est_xy[i] - reference[j].bh_xy_m).norm();
      if (d <= o.match_m) pairs.emplace_back(d, i, j);
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<long> est_match(estimate.size(), -1), ref_match(reference.size(), -1);
  for (const auto& [d, i, j] : pairs) {
    if (est_match[i] >= 0 || ref_match[j] >= 0) continue;
    est_match[i] = static_cast<long>(j);
    ref_match[j] = static_cast<long>(i);
  }

  a.by_dbh = {{"DBH 10-20 cm"}, {"DBH 20-30 cm"}, {"DBH 30-40 cm"}, {"DBH >= 40 cm"}};
  const double step_m = o.max_path_distance_m / 3.0;
  for (int k = 0; k < 3; ++k)
    a.by_distance.push_back(
        {fmt::format("{:.0f}-{:.0f} m from the path", k * step_m, (k + 1) * step_m)});
  double dbh_sq = 0, dbh_sum = 0, pos_sq = 0, height_sq = 0, height_sum = 0;
  std::size_t heights = 0, overlapping = 0, with_sigma = 0, within_2_sigma = 0;
  for (std::size_t j = 0; j < reference.size(); ++j) {
    const trees::TreeRecord& ref = reference[j];
    const double distance_m = pathDistance(ref.bh_xy_m, reference_path_m);
    if (ref.dbh_m < o.min_dbh_m || distance_m > o.max_path_distance_m) continue;
    ++a.reference;
    const bool found = ref_match[j] >= 0;
    TreeClass& by_dbh = a.by_dbh[dbhClass(ref.dbh_m)];
    TreeClass& by_distance =
        a.by_distance[std::min<std::size_t>(2, static_cast<std::size_t>(distance_m / step_m))];
    ++by_dbh.reference;
    ++by_distance.reference;
    if (!found) {
      a.missed_xy_m.push_back(ref.bh_xy_m);
      a.missed_ids.push_back(ref.id);
      continue;
    }
    ++a.detected;
    ++by_dbh.detected;
    ++by_distance.detected;
    const auto i = static_cast<std::size_t>(ref_match[j]);
    const trees::TreeRecord& est = estimate[i];
    const double dbh_error = est.dbh_m * T.scale - ref.dbh_m;
    dbh_sq += dbh_error * dbh_error;
    dbh_sum += dbh_error;
    if (est.dbh_sigma_m > 0.0) {  // false for NaN: a file without the column
      ++with_sigma;
      if (std::abs(dbh_error) <= 2.0 * est.dbh_sigma_m * T.scale) ++within_2_sigma;
    }
    const double position_error = (est_xy[i] - ref.bh_xy_m).norm();
    pos_sq += position_error * position_error;
    if (position_error < 0.5 * (est.dbh_m + ref.dbh_m)) ++overlapping;
    if (!std::isnan(est.height_m) && !std::isnan(ref.height_m)) {
      const double e = est.height_m - ref.height_m;
      height_sq += e * e;
      height_sum += e;
      ++heights;
    }
    a.matches.push_back({est.id, ref.id, est_xy[i], ref.bh_xy_m, est.dbh_m, ref.dbh_m, distance_m});
  }
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    if (pathDistance(est_xy[i], reference_path_m) > o.max_path_distance_m) continue;
    ++a.estimated;
    if (est_match[i] < 0) {
      ++a.false_stems;
      a.false_xy_m.push_back(est_xy[i]);
      a.false_ids.push_back(estimate[i].id);
    }
  }
  const auto n = static_cast<double>(a.detected);
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  a.recall = a.reference > 0 ? n / static_cast<double>(a.reference) : kNaN;
  a.commission = a.estimated > 0 ? static_cast<double>(a.false_stems) / a.estimated : kNaN;
  a.dbh_rmse_m = a.detected > 0 ? std::sqrt(dbh_sq / n) : kNaN;
  a.dbh_bias_m = a.detected > 0 ? dbh_sum / n : kNaN;
  a.dbh_within_2_sigma =
      with_sigma > 0 ? static_cast<double>(within_2_sigma) / static_cast<double>(with_sigma) : kNaN;
  a.position_rmse_m = a.detected > 0 ? std::sqrt(pos_sq / n) : kNaN;
  a.height_rmse_m = heights > 0 ? std::sqrt(height_sq / static_cast<double>(heights)) : kNaN;
  a.height_bias_m = heights > 0 ? height_sum / static_cast<double>(heights) : kNaN;
  a.overlap_ratio = a.reference > 0 ? static_cast<double>(overlapping) / a.reference : kNaN;
  return a;
}

}  // namespace taiga::eval
