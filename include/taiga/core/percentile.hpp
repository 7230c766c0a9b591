#pragma once
// Percentiles with numpy's definition, used by the evaluation (evo prints numpy's) and by the
// run's timing summary alike.

#include <span>

namespace taiga {

/// The p-th percentile (p in [0, 100]) as numpy.percentile with its default linear method:
/// rank r = p / 100 * (n - 1) into the sorted values, interpolated between floor(r) and ceil(r).
/// NaN when `values` is empty.
double percentile(std::span<const double> values, double p);

/// A standard deviation robust to outliers: 1.4826 times the median absolute deviation from the
/// median (the factor makes it the sigma of a normal distribution). NaN when `values` is empty.
double robustSigma(std::span<const double> values);

}  // namespace taiga
