#pragma once
// Summary statistics of a list of errors, with the definitions evo prints (numpy's): population
// standard deviation (ddof = 0), the median as the mean of the two middle values for an even
// count, and percentiles by linear interpolation between the closest ranks.

#include <cstddef>
#include <span>

#include "taiga/core/percentile.hpp"

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

using taiga::percentile;  // core/percentile.hpp

}  // namespace taiga::eval
