// A stem's section in an NDT cell: Taubin's circle fit to the cell's horizontal moments
// (G. Taubin, "Estimation of planar curves, surfaces and nonplanar space curves defined by
// implicit equations", IEEE PAMI 1991; the moment form and Newton solve as in N. Chernov,
// "Circular and Linear Regression", CRC 2010, ch. 5), and the gates that keep it to stems.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <span>

#include "taiga/registration/ndt.hpp"

namespace taiga::registration {
namespace {

struct Circle {
  Eigen::Vector2d centre_from_mean = Eigen::Vector2d::Zero();  ///< m
  double radius_m = 0.0;
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
  return std::isfinite(out.radius_m);
}

// The central moments (1/n) of the union of cells, from each cell's count, mean, covariance
// and circle moments by the parallel-axis rules to the fourth order. With a cell's horizontal
// offset a from a common origin, its points' d about its mean (E[d] = 0, E[d d^T] = P,
// E[d w_d] = t, E[w_d^2] = q) and x = a + d, w = |x|^2:
//   E[x w]   = a |a|^2 + a tr P + 2 P a + t
//   E[w^2]   = |a|^4 + 4 a^T P a + 2 |a|^2 tr P + 4 a.t + q,
// the same rules read backwards about the union's mean give its central moments.
struct Raw {
  Eigen::Vector2d xw;
  double ww;
};
Raw aboutOffset(const Eigen::Vector2d& a, const Eigen::Matrix2d& P, const Eigen::Vector2d& t,
                double q) {
  const double aa = a.squaredNorm(), trP = P.trace();
  return {a * aa + a * trP + 2.0 * P * a + t,
          aa * aa + 4.0 * a.dot(P * a) + 2.0 * aa * trP + 4.0 * a.dot(t) + q};
}

CellMoments unionOf(std::span<const CellMoments* const> cells) {
  CellMoments u;
  const Eigen::Vector3d origin = cells[0]->mean;
  Eigen::Vector3d sum_x = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_xx = Eigen::Matrix3d::Zero();
  Eigen::Vector2d sum_xw = Eigen::Vector2d::Zero();
  double sum_ww = 0.0;
  for (const CellMoments* m : cells) {
    const double n = static_cast<double>(m->count);
    const Eigen::Vector3d a = m->mean - origin;
    const Eigen::Matrix3d P = m->covariance * ((n - 1.0) / n);
    const Raw raw = aboutOffset(a.head<2>(), P.topLeftCorner<2, 2>(), {m->xw, m->yw}, m->ww);
    u.count += m->count;
    sum_x += n * a;
    sum_xx += n * (P + a * a.transpose());
    sum_xw += n * raw.xw;
    sum_ww += n * raw.ww;
  }
  const double n = static_cast<double>(u.count);
  const Eigen::Vector3d M = sum_x / n;
  const Eigen::Matrix3d P = sum_xx / n - M * M.transpose();
  u.mean = origin + M;
  u.covariance = P * (n / (n - 1.0));
  // Central moments about M: E[x w] and E[w^2] about the origin minus the offset's terms.
  const Eigen::Matrix2d P2 = P.topLeftCorner<2, 2>();
  const Raw offset = aboutOffset(M.head<2>(), P2, Eigen::Vector2d::Zero(), 0.0);
  const Eigen::Vector2d t = sum_xw / n - offset.xw;
  u.xw = t.x();
  u.yw = t.y();
  u.ww = sum_ww / n - offset.ww - 4.0 * M.head<2>().dot(t);
  return u;
}

/// E[(|x - c|^2 - R^2)^2] / 4 R^2 over the cell's points, from its moments: the variance of their
/// distance to the circle (d - R ~ (d^2 - R^2) / 2R near it).
double residualVariance(const CellMoments& m, const Eigen::Vector2d& centre, double radius_m) {
  const double n = static_cast<double>(m.count);
  const Eigen::Matrix2d P = m.covariance.topLeftCorner<2, 2>() * ((n - 1.0) / n);
  const Eigen::Vector2d b = m.mean.head<2>() - centre;
  const double k = b.squaredNorm() - radius_m * radius_m;
  const double e4 = k * k + 4.0 * b.dot(P * b) + 2.0 * k * P.trace() +
                    4.0 * b.dot(Eigen::Vector2d(m.xw, m.yw)) + m.ww;
  return std::max(e4, 0.0) / (4.0 * radius_m * radius_m);
}

/// The residual gate: points whose distance variance about a circle of radius r is this small
/// lie on it (RMS under a quarter of the radius and 4 cm; false for NaN).
bool liesOnCircle(double residual_variance_m2, double radius_m) {
  const double rms = std::sqrt(residual_variance_m2);
  return rms <= 0.25 * radius_m && rms <= 0.04;
}

struct StemCircle {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< m, in the frame of the points
  double radius_m = 0.0;
  double residual_variance_m2 = 0.0;
};

/// The section's moments without the range noise's share (CellMoments::noise_xx ...; zero for
/// points added without their beams): the circle is fitted to these, and its gates judge them.
CellMoments withoutNoise(const CellMoments& m) {
  if (m.count < 2) return m;
  CellMoments clean = m;
  const double n = static_cast<double>(m.count);
  clean.covariance.topLeftCorner<2, 2>() -= m.noise_xx * (n / (n - 1.0));
  // A stated noise larger than the section's own spread along the beams (a datasheet's
  // worst case, or a unit error) would leave a negative variance: the section is then fitted
  // as it was measured.
  const Eigen::Matrix2d horizontal = clean.covariance.topLeftCorner<2, 2>();
  if (!(horizontal(0, 0) > 0.0 && horizontal.determinant() > 0.0)) return m;
  clean.xw -= m.noise_xw;
  clean.yw -= m.noise_yw;
  clean.ww -= m.noise_ww;
  clean.noise_xx.setZero();
  clean.noise_xw = clean.noise_yw = clean.noise_ww = 0.0;
  return clean;
}

/// The circle of a section's moments and the first gate of fitStemSection it fails (kStem: none).
/// The residual variance kept with the circle is the points' own (noise included): it weighs the
/// distances of a scan's points, which are noisy too.
struct GatedCircle {
  StemGate gate = StemGate::kStem;
  StemCircle circle;
};
GatedCircle gatedCircle(const CellMoments& noisy, double resolution_m) {
  constexpr std::size_t kMinPoints = 10;
  constexpr double kMinRadius_m = 0.03;
  constexpr double kMaxRadiusShare = 0.5;  // of the cell edge
  constexpr double kMinArcSpread = 0.15;   // largest horizontal variance / R^2: about 80 deg
  constexpr double kMaxLean = 0.25;        // horizontal drift of the section per m of height
  if (noisy.count < kMinPoints) return {StemGate::kFewPoints};
  const CellMoments m = withoutNoise(noisy);
  const double n = static_cast<double>(m.count);
  const Eigen::Matrix3d C = m.covariance * ((n - 1.0) / n);
  const double var_z = C(2, 2);
  if (!(var_z > 0.0)) return {StemGate::kLeaning};
  if (std::hypot(C(0, 2), C(1, 2)) / var_z > kMaxLean) return {StemGate::kLeaning};
  Circle circle;
  if (!taubin(C(0, 0), C(1, 1), C(0, 1), m.xw, m.yw, m.ww, circle)) return {StemGate::kNoCircle};
  const double r = circle.radius_m;
  if (!(r >= kMinRadius_m && r <= kMaxRadiusShare * resolution_m)) return {StemGate::kRadius};
  const Eigen::Vector2d centre = m.mean.head<2>() + circle.centre_from_mean;
  if (!liesOnCircle(residualVariance(m, centre, r), r)) return {StemGate::kResidual};
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> horizontal(C.topLeftCorner<2, 2>(),
                                                                   Eigen::EigenvaluesOnly);
  if (horizontal.eigenvalues()(1) < kMinArcSpread * r * r) return {StemGate::kShortArc};
  return {StemGate::kStem, StemCircle{centre, r, residualVariance(noisy, centre, r)}};
}

/// The circle of a section's moments when it passes the stem gates (fitStemSection).
std::optional<StemCircle> stemCircle(const CellMoments& m, double resolution_m) {
  const GatedCircle gated = gatedCircle(m, resolution_m);
  if (gated.gate != StemGate::kStem) return std::nullopt;
  return gated.circle;
}

void makeStemCell(const StemCircle& circle, double min_variance_m2, NdtCell& cell) {
  // The radial variance is floored as the Gaussian's eigenvalues are; the vertical one is the
  // cell's.
  cell.stem = true;
  cell.stem_centre = circle.centre;
  cell.stem_radius_m = circle.radius_m;
  cell.inverse_radial_variance = 1.0 / std::max(circle.residual_variance_m2, min_variance_m2);
  cell.inverse_vertical_variance = 1.0 / cell.covariance(2, 2);
}

}  // namespace

bool fitStemSection(const CellMoments& m, double resolution_m, double min_variance_m2,
                    NdtCell& cell) {
  const std::optional<StemCircle> circle = stemCircle(m, resolution_m);
  if (!circle) return false;
  makeStemCell(*circle, min_variance_m2, cell);
  return true;
}

StemGate stemGateOf(const CellMoments& m, double resolution_m) {
  return gatedCircle(m, resolution_m).gate;
}

bool fitStemSectionAcross(const CellMoments& own, std::span<const CellMoments* const> block,
                          double resolution_m, double min_variance_m2, NdtCell& cell) {
  const std::optional<StemCircle> circle = stemCircle(unionOf(block), resolution_m);
  if (!circle) return false;
  if (!liesOnCircle(residualVariance(own, circle->centre, circle->radius_m), circle->radius_m)) {
    return false;
  }
  makeStemCell(*circle, min_variance_m2, cell);
  return true;
}

}  // namespace taiga::registration
