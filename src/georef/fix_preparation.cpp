#include "taiga/georef/fix_preparation.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

namespace taiga::georef {
namespace {

void requirePositive(double value, const char* field) {
  if (!(std::isfinite(value) && value > 0.0))
    throw std::invalid_argument(fmt::format("georef gating: {} must be positive, got {}", field, value));
}

bool isValid(const GnssFix& fix) {
  return std::isfinite(fix.t_s) && std::isfinite(fix.latitude_deg) &&
         std::isfinite(fix.longitude_deg) && std::isfinite(fix.height_ellipsoid_m) &&
         std::abs(fix.latitude_deg) <= 90.0 && std::abs(fix.longitude_deg) <= 180.0 &&
         std::abs(fix.height_ellipsoid_m) < 1e5;
}

/// The fix's covariance, or the default one when the receiver reported none. Returns nothing when
/// a reported covariance is not a finite, positive-definite matrix.
std::optional<Eigen::Matrix3d> usableCovariance(const GnssFix& fix, const FixGating& gating) {
  if (fix.covariance_type == GnssCovarianceType::kUnknown) {
    const double h2 = gating.default_horizontal_sigma_m * gating.default_horizontal_sigma_m;
    const double v2 = gating.default_vertical_sigma_m * gating.default_vertical_sigma_m;
    return Eigen::Vector3d(h2, h2, v2).asDiagonal().toDenseMatrix();
  }
  if (!fix.covariance_enu_m2.allFinite()) return std::nullopt;
  const Eigen::Matrix3d symmetric = 0.5 * (fix.covariance_enu_m2 + fix.covariance_enu_m2.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(symmetric, Eigen::EigenvaluesOnly);
  if (!(solver.eigenvalues().minCoeff() > 0.0)) return std::nullopt;
  return symmetric;
}

}  // namespace

void FixGating::validate() const {
  requirePositive(max_horizontal_sigma_m, "max_horizontal_sigma_m");
  requirePositive(default_horizontal_sigma_m, "default_horizontal_sigma_m");
  requirePositive(default_vertical_sigma_m, "default_vertical_sigma_m");
}

double horizontalSigma(const Eigen::Matrix3d& covariance_enu_m2) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(
      covariance_enu_m2.topLeftCorner<2, 2>(), Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, solver.eigenvalues().maxCoeff()));
}

PreparedFixes prepareFixes(const std::vector<GnssFix>& fixes, const FixGating& gating,
                           const geo::CoordinateConverter& converter,
                           const std::optional<geo::Geodetic>& origin) {
  PreparedFixes prepared;
  prepared.total = fixes.size();
  std::optional<geo::Geodetic> chosen_origin = origin;
  for (const GnssFix& fix : fixes) {
    if (fix.status == GnssStatus::kNoFix) {
      ++prepared.gated_no_fix;
      continue;
    }
    const std::optional<Eigen::Matrix3d> covariance = usableCovariance(fix, gating);
    if (!isValid(fix) || !covariance) {
      ++prepared.gated_invalid;
      continue;
    }
    if (horizontalSigma(*covariance) > gating.max_horizontal_sigma_m) {
      ++prepared.gated_sigma;
      continue;
    }
    const geo::Geodetic point{fix.latitude_deg, fix.longitude_deg, fix.height_ellipsoid_m};
    if (!chosen_origin) chosen_origin = point;
    prepared.fixes.push_back({fix.t_s, converter.toEnu(*chosen_origin, point), *covariance});
  }
  if (chosen_origin) prepared.origin = *chosen_origin;
  return prepared;
}

}  // namespace taiga::georef
