#include "taiga/eval/map_sharpness.hpp"

#include <algorithm>
#include <cmath>

#include "taiga/core/errors.hpp"

namespace taiga::eval {
namespace {

/// Linear interpolation between order statistics (numpy's default percentile).
double percentileOfSorted(const std::vector<double>& sorted, double p) {
  const double rank = p * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(rank);
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (rank - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

}  // namespace

MapSharpness computeMapSharpness(const std::vector<Eigen::Vector3d>& points_est,
                                 std::size_t map_points, const AlignmentTransform& transform,
                                 const SurfaceDistance& distance,
                                 const MapSharpnessOptions& options) {
  if (points_est.empty()) throw InputError("map sharpness: the map has no points");
  MapSharpness result;
  result.map_points = map_points;
  result.cap_m = options.cap_m;
  result.transform = transform;
  std::vector<double> distances;
  distances.reserve(points_est.size());
  std::size_t beyond = 0;
  double sum = 0.0, sum2 = 0.0;
  for (const Eigen::Vector3d& p_est : points_est) {
    const Eigen::Vector3d p_ref = transform.T_ref_est * (transform.scale * p_est);
    // Asked slightly beyond the cap, so that "beyond" is told apart from "at" the cap.
    const double d = distance(p_ref, 1.01 * options.cap_m);
    if (d > options.cap_m) ++beyond;
    const double capped = std::min(d, options.cap_m);
    distances.push_back(capped);
    sum += capped;
    sum2 += capped * capped;
  }
  const auto n = static_cast<double>(distances.size());
  result.points_scored = distances.size();
  result.rms_m = std::sqrt(sum2 / n);
  result.mean_m = sum / n;
  result.fraction_beyond_cap = static_cast<double>(beyond) / n;
  std::sort(distances.begin(), distances.end());
  result.median_m = percentileOfSorted(distances, 0.5);
  result.p95_m = percentileOfSorted(distances, 0.95);
  return result;
}

}  // namespace taiga::eval
