#pragma once
// Summary statistics of a list of errors, with the definitions evo prints (numpy's): population
// standard deviation (ddof = 0), the median as the mean of the two middle values for an even
// count, and percentiles by linear interpolation between the closest ranks.

#include <cstddef>
#include <span>

namespace taiga::eval {

struct ErrorStatistics {
  std::size_t count = 0;
  double rmse = 0.0;  ///< sqrt(mean(e^2))
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;  ///< population standard deviation, as numpy.std
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  ///< sum of squared errors
};

/// Statistics of `values`; all zero (count 0) when `values` is empty. The sums run in the order
/// of `values`, so the same input gives the same bits.
ErrorStatistics computeStatistics(std::span<const double> values);

/// The p-th percentile (p in [0, 100]) as numpy.percentile with its default linear method:
/// rank r = p / 100 * (n - 1) into the sorted values, interpolated between floor(r) and ceil(r).
/// NaN when `values` is empty.
double percentile(std::span<const double> values, double p);

}  // namespace taiga::eval
