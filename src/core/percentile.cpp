#include "taiga/core/percentile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace taiga {

double percentile(std::span<const double> values, double p) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<double> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  const double rank = p / 100.0 * static_cast<double>(sorted.size() - 1);
  const auto lower = static_cast<std::size_t>(std::floor(rank));
  const std::size_t upper = std::min(lower + 1, sorted.size() - 1);
  const double fraction = rank - static_cast<double>(lower);
  const double a = sorted[lower], b = sorted[upper];
  // numpy's _lerp: from the nearer end, so that the result stays within [a, b] bit for bit.
  return fraction >= 0.5 ? b - (b - a) * (1.0 - fraction) : a + (b - a) * fraction;
}

double robustSigma(std::span<const double> values) {
  const double median = percentile(values, 50.0);
  std::vector<double> deviations(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) deviations[i] = std::abs(values[i] - median);
  return 1.4826 * percentile(deviations, 50.0);
}

}  // namespace taiga
