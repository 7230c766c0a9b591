#include "taiga/eval/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace taiga::eval {

ErrorStatistics computeStatistics(std::span<const double> values) {
  ErrorStatistics s;
  s.count = values.size();
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  double sum = 0.0, sse = 0.0;
  s.min = values.front();
  s.max = values.front();
  for (const double v : values) {
    sum += v;
    sse += v * v;
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  s.mean = sum / n;
  s.sse = sse;
  s.rmse = std::sqrt(sse / n);
  double squared_deviations = 0.0;
  for (const double v : values) squared_deviations += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(squared_deviations / n);
  std::vector<double> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  const std::size_t half = sorted.size() / 2;
  s.median = sorted.size() % 2 == 1 ? sorted[half] : (sorted[half - 1] + sorted[half]) / 2.0;
  return s;
}

}  // namespace taiga::eval
