#pragma once
// GNSS fixes made ready for fitting: gated by their reported quality, converted to a local
// east-north-up (ENU) frame at an origin so that the fit works with small numbers (thesis 3.1.3;
// projected coordinates are 10^6 m, and squaring them in normal equations loses digits), and
// associated with a trajectory by time.
//
// The ENU frame is the one of geo::CoordinateConverter::toEnu: x east, y north, z along the
// ellipsoid normal at the origin, exact through ECEF. Fixes keep their reported covariance, which
// the receiver gives in the ENU frame at the fix; over a plot (< a few km) the ENU frames at the
// fix and at the origin differ by less than 0.05 deg, so the covariance is used as it is.

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/geo/coordinates.hpp"

namespace taiga::georef {

struct FixGating {
  /// Fixes whose reported horizontal sigma (square root of the larger eigenvalue of the
  /// east-north covariance block) exceeds this are not used, m.
  double max_horizontal_sigma_m = 5.0;
  /// Covariance assumed for fixes that report none (covariance type unknown, or a CSV file
  /// without sigma columns): 1-sigma horizontal and vertical, m.
  double default_horizontal_sigma_m = 2.0;
  double default_vertical_sigma_m = 4.0;
  /// Throws std::invalid_argument naming the field when a value is not positive and finite.
  void validate() const;
};

/// One usable fix in the local ENU frame.
struct LocalFix {
  double t_s = 0.0;
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();                  ///< antenna position, m
  Eigen::Matrix3d covariance_enu_m2 = Eigen::Matrix3d::Identity();  ///< m^2
};

struct PreparedFixes {
  geo::Geodetic origin;  ///< origin of the local ENU frame
  std::vector<LocalFix> fixes;
  std::size_t total = 0;               ///< fixes given
  std::size_t gated_no_fix = 0;        ///< status kNoFix
  std::size_t gated_sigma = 0;         ///< reported horizontal sigma above the limit
  std::size_t gated_invalid = 0;       ///< non-finite or out-of-range coordinates or covariance
  std::size_t gated() const { return gated_no_fix + gated_sigma + gated_invalid; }
};

/// Gates `fixes` and converts the others to ENU at `origin`, or at the first fix that passes the
/// gate when no origin is given. Pure: no I/O, no logging. Returns no fixes (and the default
/// origin) when none passes; callers turn that into an error naming their input.
PreparedFixes prepareFixes(const std::vector<GnssFix>& fixes, const FixGating& gating,
                           const geo::CoordinateConverter& converter,
                           const std::optional<geo::Geodetic>& origin = std::nullopt);

/// sqrt of the larger eigenvalue of the east-north block of an ENU covariance, m.
double horizontalSigma(const Eigen::Matrix3d& covariance_enu_m2);

}  // namespace taiga::georef
