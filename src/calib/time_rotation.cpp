#include "taiga/calib/time_rotation.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "taiga/core/errors.hpp"
#include "taiga/core/percentile.hpp"
#include "taiga/imu/readings.hpp"
#include "taiga/lie/umeyama.hpp"

namespace taiga::calib {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
constexpr int kParams = 7;  // [offset (s), rotation (rad, left perturbation of R_c), bias (rad/s)]
using ParamMatrix = Eigen::Matrix<double, kParams, kParams>;
using ParamVector = Eigen::Matrix<double, kParams, 1>;
using Basis = Eigen::Matrix<double, kParams, Eigen::Dynamic>;

struct State {
  double offset_s = 0.0;
  Matrix3d R_c = Matrix3d::Identity();
  Vector3d bias_radps = Vector3d::Zero();
};

/// Residual (1) of every used increment at one state, with its Jacobian rows.
class Problem {
 public:
  Problem(std::vector<RotationIncrement> increments, const std::vector<GyroReading>& gyro)
      : increments_(std::move(increments)), gyro_(gyro) {}

  std::size_t size() const { return increments_.size(); }
  const RotationIncrement& increment(std::size_t k) const { return increments_[k]; }
  double duration(std::size_t k) const { return increments_[k].t1_s - increments_[k].t0_s; }

  Vector3d gyroRotation(std::size_t k, double offset_s, const Vector3d& bias) const {
    const RotationIncrement& inc = increments_[k];
    return integrateGyro(gyro_, inc.t0_s + offset_s, inc.t1_s + offset_s, bias).Log();
  }
  Vector3d residual(std::size_t k, const State& s) const {
    return gyroRotation(k, s.offset_s, s.bias_radps) - s.R_c * increments_[k].theta_body_rad;
  }
  /// d r_k / d [offset, theta, bias]: numeric in offset and bias, r = g - Exp(theta) R_c l gives
  /// +[R_c l]x in theta.
  Eigen::Matrix<double, 3, kParams> jacobian(std::size_t k, const State& s) const {
    Eigen::Matrix<double, 3, kParams> J;
    constexpr double kOffsetStep_s = 2e-4, kBiasStep_radps = 1e-4;
    J.col(0) = (gyroRotation(k, s.offset_s + kOffsetStep_s, s.bias_radps) -
                gyroRotation(k, s.offset_s - kOffsetStep_s, s.bias_radps)) /
               (2.0 * kOffsetStep_s);
    J.block<3, 3>(0, 1) = lie::hat(s.R_c * increments_[k].theta_body_rad);
    for (int i = 0; i < 3; ++i) {
      const Vector3d step = kBiasStep_radps * Vector3d::Unit(i);
      J.col(4 + i) = (gyroRotation(k, s.offset_s, s.bias_radps + step) -
                      gyroRotation(k, s.offset_s, s.bias_radps - step)) /
                     (2.0 * kBiasStep_radps);
    }
    return J;
  }
  /// Whether increment k+lag directly follows k (they share a scan, so their errors correlate).
  bool follows(std::size_t k, std::size_t lag) const {
    if (k + lag >= increments_.size()) return false;
    for (std::size_t i = k; i < k + lag; ++i)
      if (std::abs(increments_[i + 1].t0_s - increments_[i].t1_s) > 1e-6) return false;
    return true;
  }
  void keep(const std::vector<bool>& inlier) {
    std::vector<RotationIncrement> kept;
    for (std::size_t k = 0; k < increments_.size(); ++k)
      if (inlier[k]) kept.push_back(increments_[k]);
    increments_ = std::move(kept);
  }

 private:
  std::vector<RotationIncrement> increments_;
  const std::vector<GyroReading>& gyro_;
};

/// Closed-form (R_c, b) at a fixed offset: Kabsch for R_c given b, least squares for b given R_c,
/// alternated (b is small, so a few rounds suffice). Bias enters as -b * duration, to first order.
State alignAtOffset(const Problem& p, double offset_s, double* rms_radps) {
  std::vector<Vector3d> g(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) g[k] = p.gyroRotation(k, offset_s, Vector3d::Zero());
  State s{.offset_s = offset_s};
  for (int round = 0; round < 4; ++round) {
    Matrix3d H = Matrix3d::Zero();
    for (std::size_t k = 0; k < p.size(); ++k)
      H += (g[k] - s.bias_radps * p.duration(k)) * p.increment(k).theta_body_rad.transpose();
    s.R_c = lie::kabschRotation(H);
    Vector3d num = Vector3d::Zero();
    double den = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k) {
      num += p.duration(k) * (g[k] - s.R_c * p.increment(k).theta_body_rad);
      den += p.duration(k) * p.duration(k);
    }
    s.bias_radps = num / den;
  }
  double sum_r2 = 0.0, sum_dt2 = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    sum_r2 +=
        (g[k] - s.bias_radps * p.duration(k) - s.R_c * p.increment(k).theta_body_rad).squaredNorm();
    sum_dt2 += p.duration(k) * p.duration(k);
  }
  *rms_radps = std::sqrt(sum_r2 / sum_dt2);
  return s;
}

/// The profile cost over the offset grid; returns the state at its minimum.
State profileMinimum(const Problem& p, const TimeRotationOptions& o,
                     std::vector<CostPoint>* curve) {
  curve->clear();
  State best;
  double best_rms = std::numeric_limits<double>::infinity();
  const int steps = static_cast<int>(std::round(o.max_offset_s / o.grid_step_s));
  for (int i = -steps; i <= steps; ++i) {
    double rms = 0.0;
    const State s = alignAtOffset(p, i * o.grid_step_s, &rms);
    curve->push_back({.offset_s = s.offset_s, .rms_radps = rms});
    if (rms < best_rms) best_rms = rms, best = s;
  }
  return best;
}

/// A touch of Levenberg damping, so that a direction the motion leaves flat (the rotation about
/// the only axis the rig turned about) stays where it is instead of breaking the solve.
void damp(Eigen::MatrixXd& A) { A.diagonal().array() += 1e-9 * (1.0 + A.diagonal().array()); }

/// Gauss-Newton over the parameters spanned by `basis` (columns in [offset, theta, bias]).
State refine(const Problem& p, State s, const Basis& basis) {
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Eigen::Index m = basis.cols();
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m, m);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(m);
    for (std::size_t k = 0; k < p.size(); ++k) {
      const Eigen::Matrix<double, 3, Eigen::Dynamic> J = p.jacobian(k, s) * basis;
      A += J.transpose() * J;
      g += J.transpose() * p.residual(k, s);
    }
    damp(A);
    const ParamVector step = basis * A.ldlt().solve(-g);
    s.offset_s += step(0);
    s.R_c = lie::SO3::Exp(step.segment<3>(1)).matrix() * s.R_c;
    s.bias_radps += step.segment<3>(4);
    if (std::abs(step(0)) < 1e-7 && step.segment<3>(1).norm() < 1e-8) break;
  }
  return s;
}

/// Covariance of the parameters spanned by `basis`, mapped back to the full 7: the larger (per
/// diagonal) of the plain estimate sigma^2 A^-1 and the lag-2 Newey-West sandwich
/// A^-1 B A^-1, which allows for errors shared by consecutive increments.
ParamMatrix covariance(const Problem& p, const State& s, const Basis& basis) {
  const Eigen::Index m = basis.cols();
  std::vector<Eigen::VectorXd> score(p.size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m, m);
  double sum_r2 = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const Eigen::Matrix<double, 3, Eigen::Dynamic> J = p.jacobian(k, s) * basis;
    const Vector3d r = p.residual(k, s);
    A += J.transpose() * J;
    score[k] = J.transpose() * r;
    sum_r2 += r.squaredNorm();
  }
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(m, m);
  const double weights[] = {1.0, 2.0 / 3.0, 1.0 / 3.0};  // Bartlett kernel, lag 0..2
  for (std::size_t k = 0; k < p.size(); ++k) {
    B += score[k] * score[k].transpose();
    for (std::size_t lag = 1; lag <= 2; ++lag)
      if (p.follows(k, lag)) {
        const Eigen::MatrixXd cross = score[k] * score[k + lag].transpose();
        B += weights[lag] * (cross + cross.transpose());
      }
  }
  damp(A);
  const double dof = std::max(1.0, 3.0 * static_cast<double>(p.size()) - static_cast<double>(m));
  const Eigen::MatrixXd A_inv = A.inverse();
  const Eigen::MatrixXd plain = (sum_r2 / dof) * A_inv;
  Eigen::MatrixXd robust = A_inv * B * A_inv * (3.0 * static_cast<double>(p.size()) / dof);
  // Keep the robust correlations, with variances no smaller than the plain ones.
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(m);
  for (Eigen::Index i = 0; i < m; ++i)
    if (robust(i, i) > 0.0) scale(i) = std::sqrt(std::max(1.0, plain(i, i) / robust(i, i)));
  robust = scale.asDiagonal() * robust * scale.asDiagonal();
  return basis * robust * basis.transpose();
}

/// Delete-one-block jackknife over kBlocks stretches of time: the spread of the estimates without
/// each block. It takes in whatever the model leaves out (errors correlated over seconds, a
/// drifting clock); on simulated recordings the model's covariance alone was 2-4 times too small
/// for the offset. Only the diagonal is filled.
ParamMatrix jackknife(const Problem& p, const State& s, const Basis& basis) {
  constexpr int kBlocks = 6;
  const double t0 = p.increment(0).t0_s, t1 = p.increment(p.size() - 1).t1_s;
  std::vector<ParamVector> estimates;
  for (int block = 0; block < kBlocks; ++block) {
    std::vector<bool> keep(p.size());
    std::size_t kept = 0;
    for (std::size_t k = 0; k < p.size(); ++k) {
      const int b =
          std::min(kBlocks - 1, static_cast<int>(kBlocks * (p.increment(k).t0_s - t0) / (t1 - t0)));
      keep[k] = b != block;
      kept += keep[k];
    }
    if (kept < 20 || kept == p.size()) continue;
    Problem without = p;
    without.keep(keep);
    const State r = refine(without, s, basis);
    ParamVector x;
    x << r.offset_s, lie::SO3::fromMatrix(r.R_c * s.R_c.transpose()).Log(), r.bias_radps;
    estimates.push_back(x);
  }
  ParamMatrix variance = ParamMatrix::Zero();
  if (estimates.size() < 3) return variance;
  ParamVector mean = ParamVector::Zero();
  for (const ParamVector& x : estimates) mean += x / static_cast<double>(estimates.size());
  const double n = static_cast<double>(estimates.size());
  for (const ParamVector& x : estimates)
    variance.diagonal() += ((n - 1.0) / n) * (x - mean).cwiseAbs2();
  return variance;
}

std::vector<bool> inliers(const Problem& p, const State& s, double outlier_sigmas) {
  std::vector<double> norms(p.size());
  for (std::size_t k = 0; k < p.size(); ++k) norms[k] = p.residual(k, s).norm();
  const double median = percentile(norms, 50.0);
  const double sigma = robustSigma(norms);
  std::vector<bool> keep(p.size());
  for (std::size_t k = 0; k < p.size(); ++k)
    keep[k] = norms[k] <= median + outlier_sigmas * std::max(sigma, 1e-6);
  return keep;
}

double square(double x) { return x * x; }

/// Variances that the motion itself allows, from the information its signal carries. The
/// Jacobians of (1) are built from noisy data (the gyro's rates, the registration's increments),
/// so their information counts noise as if it were motion: without motion about an axis a
/// Gauss-Newton covariance still looks finite. The noise's expected share is taken out first:
/// for the offset, 2 sigma_w^2 per component of d r / d offset (the difference of two gyro
/// readings); for the rotation, 2 sigma_r^2 per direction of sum(|v|^2 I - v v^T), v = R_c l.
struct Excitation {
  double offset_variance_s2 = 0.0;
  Matrix3d rotation_directions = Matrix3d::Identity();  ///< eigenvectors, columns
  Vector3d rotation_variances_rad2 = Vector3d::Zero();  ///< per direction; infinite: not excited
};

/// White noise of one gyro reading per component, from second differences (a smooth rate cancels
/// out; vibration does not, which errs on the side of less information).
double gyroReadingVariance(const std::vector<GyroReading>& gyro) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 1; i + 1 < gyro.size(); ++i, ++n)
    sum += (gyro[i + 1].omega_body_radps - 2.0 * gyro[i].omega_body_radps +
            gyro[i - 1].omega_body_radps)
               .squaredNorm();
  return n > 0 ? sum / (6.0 * 3.0 * static_cast<double>(n)) : 0.0;
}

Excitation measureExcitation(const Problem& p, const State& s,
                             const std::vector<GyroReading>& gyro) {
  const double n = static_cast<double>(p.size());
  double sum_r2 = 0.0, offset_information = 0.0;
  Matrix3d rotation_information = Matrix3d::Zero();
  for (std::size_t k = 0; k < p.size(); ++k) {
    sum_r2 += p.residual(k, s).squaredNorm();
    offset_information += p.jacobian(k, s).col(0).squaredNorm();
    const Vector3d v = s.R_c * p.increment(k).theta_body_rad;
    rotation_information += v.squaredNorm() * Matrix3d::Identity() - v * v.transpose();
  }
  const double residual_variance = sum_r2 / (3.0 * n);  // per component
  offset_information -= n * 3.0 * 2.0 * gyroReadingVariance(gyro);
  // The lidar must see the rate change too: d r / d offset is the rate's change across an
  // increment, which the registration shows as the change between its neighbours' increments.
  double lidar_information = 0.0;
  for (std::size_t k = 1; k + 1 < p.size(); ++k)
    if (p.follows(k - 1, 2)) {
      const RotationIncrement &before = p.increment(k - 1), &after = p.increment(k + 1);
      const Vector3d change = after.theta_body_rad / (after.t1_s - after.t0_s) -
                              before.theta_body_rad / (before.t1_s - before.t0_s);
      // d r / d offset ~ change / 2; each increment's noise is about residual_variance per
      // component, so the change's noise adds 3 * 2 * residual_variance / dt^2 / 4.
      lidar_information +=
          0.25 * change.squaredNorm() - 1.5 * residual_variance / square(p.duration(k));
    }
  offset_information = std::min(offset_information, lidar_information);
  rotation_information -= n * 2.0 * residual_variance * Matrix3d::Identity();
  Excitation x;
  const double inf = std::numeric_limits<double>::infinity();
  x.offset_variance_s2 = offset_information > 0.0 ? residual_variance / offset_information : inf;
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(rotation_information);
  x.rotation_directions = eig.eigenvectors();
  for (int i = 0; i < 3; ++i)
    x.rotation_variances_rad2(i) =
        eig.eigenvalues()(i) > 0.0 ? residual_variance / eig.eigenvalues()(i) : inf;
  return x;
}

/// R_c without its rotation about the held directions (left perturbations, in the gyro's body
/// frame). One held direction u: the swing-twist split R_c = Twist(u) * Swing keeps the swing;
/// more than one: nothing is left to estimate, the identity.
Matrix3d withoutRotationAbout(const Matrix3d& R_c, const std::vector<Vector3d>& held) {
  if (held.empty()) return R_c;
  if (held.size() > 1) return Matrix3d::Identity();
  // For q^-1 = swing' * twist' with twist' about u, q = twist'^-1 * swing'^-1.
  const Eigen::Quaterniond q_inv = Eigen::Quaterniond(R_c).conjugate();
  const Vector3d u = held.front();
  Eigen::Quaterniond twist(q_inv.w(), 0.0, 0.0, 0.0);
  twist.vec() = q_inv.vec().dot(u) * u;
  if (twist.norm() < 1e-12) return R_c;  // a half turn exactly across u: no twist to remove
  twist.normalize();
  const Eigen::Quaterniond swing = q_inv * twist.conjugate();
  return swing.conjugate().toRotationMatrix();
}

/// Whether the motion determined a quantity well enough to replace the configured value: its
/// 1-sigma within `max_sigma`, or, for a change that is significant (at least 3 sigma), within
/// ten times that (a 5 deg mounting error found to 0.2 deg is worth taking; a 0.1 deg change
/// known to 0.2 deg is not).
bool determined(double change, double variance, double max_sigma) {
  const double sigma = std::sqrt(variance);
  return sigma <= max_sigma || (sigma <= 10.0 * max_sigma && std::abs(change) >= 3.0 * sigma);
}

/// The parameters left free: the offset when observable, the rotation directions the motion
/// determined (the others go to `held`), the gyro bias always.
Basis estimationBasis(bool offset_observable, const Excitation& excitation, const Vector3d& theta,
                      const TimeRotationOptions& options, std::vector<Vector3d>* held) {
  Basis basis(kParams, 0);
  auto addColumn = [&](const ParamVector& column) {
    basis.conservativeResize(Eigen::NoChange, basis.cols() + 1);
    basis.col(basis.cols() - 1) = column;
  };
  if (offset_observable) addColumn(ParamVector::Unit(0));
  for (int i = 0; i < 3; ++i) {
    const Vector3d v = excitation.rotation_directions.col(i);
    if (determined(v.dot(theta), excitation.rotation_variances_rad2(i),
                   options.max_rotation_sigma_rad)) {
      ParamVector column = ParamVector::Zero();
      column.segment<3>(1) = v;
      addColumn(column);
    } else {
      held->push_back(v);
    }
  }
  for (int i = 0; i < 3; ++i) addColumn(ParamVector::Unit(4 + i));
  return basis;
}

/// RMS over the increments' durations of residual (1) and of the rate the registration saw.
void rmsRates(const Problem& p, const State& s, double* residual_radps, double* signal_radps) {
  double sum_r2 = 0.0, sum_signal2 = 0.0, sum_dt2 = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    sum_r2 += p.residual(k, s).squaredNorm();
    sum_signal2 += p.increment(k).theta_body_rad.squaredNorm();
    sum_dt2 += p.duration(k) * p.duration(k);
  }
  *residual_radps = std::sqrt(sum_r2 / sum_dt2);
  *signal_radps = std::sqrt(sum_signal2 / sum_dt2);
}

const char* axisName(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

std::string advice(const TimeRotationEstimate& e) {
  std::string unexcited;
  for (int axis = 0; axis < 3; ++axis)
    if (!e.rotation_observable(axis))
      unexcited += fmt::format("{}{}", unexcited.empty() ? "" : ", ", axisName(axis));
  if (unexcited.empty() && e.offset_observable) return {};
  std::string text = "the motion was too poor to calibrate";
  if (!e.offset_observable) text += " the time offset (it needs turns that speed up and slow down)";
  if (!unexcited.empty())
    text += fmt::format("{} the rotation about the body's {} axis",
                        e.offset_observable ? "" : " and", unexcited);
  return text +
         ": rotate the rig about all three axes, back and forth, for 10 s (a handheld scanner: "
         "tilt it left-right and forward-back while turning) and calibrate on that stretch";
}

}  // namespace

Eigen::Vector3<bool> axesNotHeld(const std::vector<Eigen::Vector3d>& held) {
  Eigen::Vector3<bool> observable(true, true, true);
  for (const Vector3d& v : held)
    for (int axis = 0; axis < 3; ++axis)
      if (v(axis) * v(axis) > 1.0 / 3.0) observable(axis) = false;
  return observable;
}

std::string axisNames(const Eigen::Vector3<bool>& which) {
  std::string names;
  for (int axis = 0; axis < 3; ++axis)
    if (which(axis)) names += axisName(axis);
  return names;
}

std::string axisNamesOrNone(const Eigen::Vector3<bool>& which) {
  const std::string names = axisNames(which);
  return names.empty() ? "none" : names;
}

lie::SO3 integrateGyro(const std::vector<GyroReading>& gyro, double t0_s, double t1_s,
                       const Eigen::Vector3d& bias_radps) {
  if (gyro.empty() || gyro.front().t_s > t0_s || gyro.back().t_s < t1_s)
    throw InputError(fmt::format("gyro readings do not cover {:.3f}-{:.3f} s", t0_s, t1_s));
  Matrix3d R = Matrix3d::Identity();
  imu::forEachPiece(
      gyro, t0_s, t1_s, [](const GyroReading& g) { return g.omega_body_radps; },
      [&](double t_from_s, double t_to_s, const Vector3d& mean) {
        R = R * lie::SO3::Exp((mean - bias_radps) * (t_to_s - t_from_s)).matrix();
      });
  return lie::SO3::fromMatrix(R);
}

TimeRotationEstimate estimateTimeRotation(const std::vector<RotationIncrement>& increments,
                                          const std::vector<GyroReading>& gyro,
                                          const TimeRotationOptions& options) {
  // Only increments the gyro covers at every offset of the grid.
  std::vector<RotationIncrement> covered;
  for (const RotationIncrement& inc : increments)
    if (!gyro.empty() && inc.t1_s > inc.t0_s &&
        inc.t0_s - options.max_offset_s > gyro.front().t_s &&
        inc.t1_s + options.max_offset_s < gyro.back().t_s)
      covered.push_back(inc);
  constexpr std::size_t kMinIncrements = 20;
  if (covered.size() < kMinIncrements)
    throw InputError(fmt::format(
        "calibration: {} scan-to-scan rotations with gyro readings around them (of {}); at least "
        "{} are needed",
        covered.size(), increments.size(), kMinIncrements));

  TimeRotationEstimate e;
  Problem problem(std::move(covered), gyro);
  const std::size_t all = problem.size();
  State s = profileMinimum(problem, options, &e.cost_curve);
  problem.keep(inliers(problem, s, options.outlier_sigmas));
  if (problem.size() < kMinIncrements)
    throw InputError(
        fmt::format("calibration: only {} of {} scan-to-scan rotations agree with the gyro",
                    problem.size(), all));
  e.increments_used = problem.size();
  e.increments_dropped = all - problem.size();
  if (e.increments_dropped > 0) s = profileMinimum(problem, options, &e.cost_curve);
  s = refine(problem, s, ParamMatrix::Identity());

  // What the motion excited, with the noise's share taken out.
  const Excitation excitation = measureExcitation(problem, s, gyro);
  e.offset_observable =
      determined(s.offset_s, excitation.offset_variance_s2, options.max_offset_sigma_s) &&
      std::abs(s.offset_s) < options.max_offset_s;
  if (!e.offset_observable) s = alignAtOffset(problem, 0.0, &e.residual_rms_radps);
  // Rotation: the directions the motion determined are estimated, the others held.
  std::vector<Vector3d> held;
  const Basis basis = estimationBasis(e.offset_observable, excitation,
                                      lie::SO3::fromMatrix(s.R_c).Log(), options, &held);
  s.R_c = withoutRotationAbout(s.R_c, held);
  s = refine(problem, s, basis);
  ParamMatrix cov = covariance(problem, s, basis);
  cov.diagonal() = cov.diagonal().cwiseMax(jackknife(problem, s, basis).diagonal());

  e.offset_s = s.offset_s;
  e.offset_sigma_s = std::sqrt(std::max(cov(0, 0), excitation.offset_variance_s2));
  e.R_correction = lie::SO3::fromMatrix(s.R_c);
  Matrix3d rotation_floor = Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    const Vector3d v = excitation.rotation_directions.col(i);
    rotation_floor += excitation.rotation_variances_rad2(i) * v * v.transpose();
  }
  e.rotation_sigma_rad =
      cov.diagonal().segment<3>(1).cwiseMax(rotation_floor.diagonal()).cwiseSqrt();
  e.rotation_observable = axesNotHeld(held);
  e.gyro_bias_radps = s.bias_radps;
  rmsRates(problem, s, &e.residual_rms_radps, &e.signal_rms_radps);
  e.advice = advice(e);
  return e;
}

}  // namespace taiga::calib
