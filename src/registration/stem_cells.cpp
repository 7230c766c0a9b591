// A stem's section in an NDT cell: Taubin's circle fit to the cell's horizontal moments
// (G. Taubin, "Estimation of planar curves, surfaces and nonplanar space curves defined by
// implicit equations", IEEE PAMI 1991; the moment form and Newton solve as in N. Chernov,
// "Circular and Linear Regression", CRC 2010, ch. 5), and the gates that keep it to stems.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "taiga/registration/ndt.hpp"

namespace taiga::registration {
namespace {

struct Circle {
  Eigen::Vector2d centre_from_mean = Eigen::Vector2d::Zero();  ///< m
  double radius_m = 0.0;
  double residual_variance_m2 = 0.0;  ///< of a point's distance to the circle
};

// Central moments (1/n) of the section: xx, yy, xy in m^2, xw, yw in m^3, ww in m^4, w = x^2+y^2.
bool taubin(double xx, double yy, double xy, double xw, double yw, double ww, Circle& out) {
  // The Taubin eigenvalue eta is the smallest root of the cubic A0 + A1 eta + A2 eta^2 +
  // A3 eta^3 (Chernov Eq. 5.40), found by Newton from 0, where the cubic is decreasing.
  const double mz = xx + yy;
  const double cov_xy = xx * yy - xy * xy;
  const double var_z = ww - mz * mz;
  const double a3 = 4.0 * mz;
  const double a2 = -3.0 * mz * mz - ww;
  const double a1 = var_z * mz + 4.0 * cov_xy * mz - xw * xw - yw * yw;
  const double a0 = xw * (xw * yy - yw * xy) + yw * (yw * xx - xw * xy) - var_z * cov_xy;
  double eta = 0.0, value = a0;
  for (int i = 0; i < 50; ++i) {
    const double slope = a1 + eta * (2.0 * a2 + 3.0 * a3 * eta);
    const double next = eta - value / slope;
    if (!std::isfinite(next) || next == eta) break;
    const double next_value = a0 + next * (a1 + next * (a2 + next * a3));
    if (std::abs(next_value) >= std::abs(value)) break;
    eta = next;
    value = next_value;
  }
  const double det = eta * eta - eta * mz + cov_xy;
  if (!(std::abs(det) > 0.0)) return false;
  const Eigen::Vector2d c((xw * (yy - eta) - yw * xy) / (2.0 * det),
                          (yw * (xx - eta) - xw * xy) / (2.0 * det));
  out.centre_from_mean = c;
  out.radius_m = std::sqrt(c.squaredNorm() + mz);
  // E[(d^2 - R^2)^2] about the fitted circle, from the moments (k = |c|^2 - R^2 = -mz), and
  // d - R ~ (d^2 - R^2) / 2R near the circle.
  const double k = -mz;
  const double e4 = ww + 4.0 * (c.x() * c.x() * xx + c.y() * c.y() * yy + 2.0 * c.x() * c.y() * xy) -
                    4.0 * (c.x() * xw + c.y() * yw) + k * k + 2.0 * k * mz;
  out.residual_variance_m2 = std::max(e4, 0.0) / (4.0 * out.radius_m * out.radius_m);
  return std::isfinite(out.radius_m) && std::isfinite(out.residual_variance_m2);
}

}  // namespace

bool fitStemSection(const CellMoments& m, double resolution_m, double min_variance_m2,
                    NdtCell& cell) {
  constexpr std::size_t kMinPoints = 10;
  constexpr double kMinRadius_m = 0.03;
  constexpr double kMaxRadiusShare = 0.5;    // of the cell edge
  constexpr double kMaxResidualShare = 0.25;  // residual RMS against the radius
  constexpr double kMaxResidual_m = 0.04;
  constexpr double kMinArcSpread = 0.15;  // largest horizontal variance / R^2: about 80 deg
  constexpr double kMaxLean = 0.25;       // horizontal drift of the section per m of height
  if (m.count < kMinPoints) return false;
  const double n = static_cast<double>(m.count);
  const Eigen::Matrix3d C = m.covariance * ((n - 1.0) / n);
  const double var_z = C(2, 2);
  if (!(var_z > 0.0)) return false;
  if (std::hypot(C(0, 2), C(1, 2)) / var_z > kMaxLean) return false;
  Circle circle;
  if (!taubin(C(0, 0), C(1, 1), C(0, 1), m.xw, m.yw, m.ww, circle)) return false;
  const double r = circle.radius_m;
  if (!(r >= kMinRadius_m && r <= kMaxRadiusShare * resolution_m)) return false;
  const double residual_rms = std::sqrt(circle.residual_variance_m2);
  if (residual_rms > kMaxResidualShare * r || residual_rms > kMaxResidual_m) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> horizontal(C.topLeftCorner<2, 2>(),
                                                                   Eigen::EigenvaluesOnly);
  if (horizontal.eigenvalues()(1) < kMinArcSpread * r * r) return false;
  // The radial variance is floored as the Gaussian's eigenvalues are; the vertical one is the
  // cell's.
  cell.stem = true;
  cell.stem_centre = m.mean.head<2>() + circle.centre_from_mean;
  cell.stem_radius_m = r;
  cell.inverse_radial_variance = 1.0 / std::max(circle.residual_variance_m2, min_variance_m2);
  cell.inverse_vertical_variance = 1.0 / cell.covariance(2, 2);
  return true;
}

}  // namespace taiga::registration
