#include "taiga/calib/gyro_noise.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "taiga/core/errors.hpp"
#include "taiga/core/percentile.hpp"

namespace taiga::calib {
namespace {

using Eigen::Vector3d;

/// Lags in scans: 0.1 to 3.5 s at 10 Hz, about evenly spaced in log(tau).
constexpr std::array<int, 9> kLags{1, 2, 3, 5, 8, 12, 17, 25, 35};
constexpr std::size_t kMinSamplesPerLag = 30;
constexpr std::size_t kMinLags = 4;
constexpr int kJackknifeBlocks = 6;

struct Sample {
  int lag_index = 0;
  double t_s = 0.0;  ///< start of the lag (the jackknife's blocks)
  double tau_s = 0.0;
  Vector3d r_rad = Vector3d::Zero();
  Vector3d theta_rad = Vector3d::Zero();          ///< the registrations' rotation over the lag
  Vector3d rate_change_radps = Vector3d::Zero();  ///< the gyro's rate at the lag's end - start
};

/// The gyro's rate at t_s, linear between readings (sorted; t_s within them).
Vector3d rateAt(const std::vector<GyroReading>& gyro, double t_s) {
  const auto after = std::lower_bound(gyro.begin(), gyro.end(), t_s,
                                      [](const GyroReading& g, double t) { return g.t_s < t; });
  if (after == gyro.begin()) return after->omega_body_radps;
  if (after == gyro.end()) return gyro.back().omega_body_radps;
  const auto before = after - 1;
  const double span_s = after->t_s - before->t_s;
  const double w = span_s > 0.0 ? (t_s - before->t_s) / span_s : 1.0;
  return (1.0 - w) * before->omega_body_radps + w * after->omega_body_radps;
}

/// The residual r(tau) of every pair of poses in a chain at the lags of kLags, with the gyro's
/// readings `gyro` (in.gyro corrected, bias removed) and `offset_s` added to the poses' times.
std::vector<Sample> residuals(const GyroNoiseInput& in, const std::vector<GyroReading>& gyro,
                              double offset_s) {
  const Eigen::Matrix3d R_c = in.R_correction.matrix();
  std::vector<Sample> samples;
  for (const std::vector<StampedPose>& chain : in.chains) {
    // The poses the gyro covers, and the gyro's rotation from the first of them to each.
    std::vector<const StampedPose*> poses;
    for (const StampedPose& p : chain)
      if (p.t_s + offset_s >= gyro.front().t_s && p.t_s + offset_s <= gyro.back().t_s)
        poses.push_back(&p);
    std::vector<lie::SO3> R_gyro(poses.size());
    for (std::size_t i = 1; i < poses.size(); ++i)
      R_gyro[i] = R_gyro[i - 1] * integrateGyro(gyro, poses[i - 1]->t_s + offset_s,
                                                poses[i]->t_s + offset_s, Vector3d::Zero());
    for (std::size_t l = 0; l < kLags.size(); ++l)
      for (std::size_t i = 0; i + kLags[l] < poses.size(); ++i) {
        const std::size_t j = i + kLags[l];
        const Eigen::Matrix3d dR_reg =
            (poses[i]->pose.rotation().inverse() * poses[j]->pose.rotation()).matrix();
        const lie::SO3 dR_gyro = R_gyro[i].inverse() * R_gyro[j];
        const lie::SO3 dR_reg_in_gyro = lie::SO3::fromMatrix(R_c * dR_reg * R_c.transpose());
        samples.push_back({.lag_index = static_cast<int>(l),
                           .t_s = poses[i]->t_s,
                           .tau_s = poses[j]->t_s - poses[i]->t_s,
                           .r_rad = (dR_reg_in_gyro.inverse() * dR_gyro).Log(),
                           .theta_rad = dR_reg_in_gyro.Log(),
                           .rate_change_radps = rateAt(gyro, poses[j]->t_s + offset_s) -
                                                rateAt(gyro, poses[i]->t_s + offset_s)});
      }
  }
  return samples;
}

/// Robust per-axis variance of each lag's residuals (1.4826 MAD, squared, mean over the axes).
std::vector<LagVariance> lagVariances(const std::vector<Sample>& samples, int skip_block,
                                      const std::vector<double>& block_edges_s) {
  std::vector<LagVariance> lags;
  for (std::size_t l = 0; l < kLags.size(); ++l) {
    std::array<std::vector<double>, 3> axis;
    double tau_sum_s = 0.0;
    for (const Sample& s : samples) {
      if (s.lag_index != static_cast<int>(l)) continue;
      if (skip_block >= 0 && s.t_s >= block_edges_s[skip_block] &&
          s.t_s < block_edges_s[skip_block + 1])
        continue;
      for (int a = 0; a < 3; ++a) axis[a].push_back(s.r_rad[a]);
      tau_sum_s += s.tau_s;
    }
    const std::size_t n = axis[0].size();
    if (n < kMinSamplesPerLag) continue;
    double variance = 0.0;
    for (const std::vector<double>& values : axis) {
      const double sigma = robustSigma(values);
      variance += sigma * sigma / 3.0;
    }
    lags.push_back(
        {.lag_scans = kLags[l], .tau_s = tau_sum_s / n, .variance_rad2 = variance, .samples = n});
  }
  return lags;
}

/// The residuals' parts explained, to first order, by errors proportional to the rotation and to
/// the change of the rate over the lag:
///   r ~ A theta + D (omega(t_end) - omega(t_start))
/// A is the gyro's scale-factor and axis errors (omega_measured = (I + A) omega; 0.5-1.5 % on
/// MEMS gyros, 2-6 mrad/s in a handheld's 0.4 rad/s of sway) and any scale error of the
/// registrations' rotations. D is what follows the rate at the scans' ends: a time offset the
/// rotation calibration left (D = -dt I; it fits no scale errors, and a drifting clock's offset is
/// only right on average), and the deskew errors those scale errors cause in each scan. Left in,
/// both grow with the lag like noise: with 1.5 % scale errors the density read 2x too high.
/// Weighted least squares (each lag's variance), samples beyond 5 robust sigmas of their lag
/// excluded. The registrations' noise is in theta as well as in r (errors in variables), which
/// pulls A towards -1 in a direction the motion hardly turned about (a machine that only slews);
/// each sample's noise adds at most about one to the normal equations' diagonal, so only their
/// eigen-directions above 100 times the sample count are fitted (a pull of under 1 %).
struct RateError {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero();
  Vector3d of(const Sample& s) const { return A * s.theta_rad + D * s.rate_change_radps; }
};

RateError fitRateError(const std::vector<Sample>& samples, const std::vector<LagVariance>& lags) {
  std::array<double, kLags.size()> variance{};
  for (const LagVariance& l : lags)
    for (std::size_t i = 0; i < kLags.size(); ++i)
      if (kLags[i] == l.lag_scans) variance[i] = l.variance_rad2;
  constexpr int kN = 18;  // A and D, column by column
  using Params = Eigen::Matrix<double, kN, 1>;
  auto jacobian = [](const Sample& s) {
    Eigen::Matrix<double, 3, kN> J;
    for (int c = 0; c < 3; ++c) {
      J.block<3, 3>(0, 3 * c) = s.theta_rad(c) * Eigen::Matrix3d::Identity();
      J.block<3, 3>(0, 9 + 3 * c) = s.rate_change_radps(c) * Eigen::Matrix3d::Identity();
    }
    return J;
  };
  Params p = Params::Zero();
  for (int round = 0; round < 2; ++round) {
    Eigen::Matrix<double, kN, kN> H = Eigen::Matrix<double, kN, kN>::Zero();
    Params g = Params::Zero();
    double count = 0.0;
    for (const Sample& s : samples) {
      const double v = variance[s.lag_index];
      if (v <= 0.0) continue;
      const Eigen::Matrix<double, 3, kN> J = jacobian(s);
      if (round > 0 && (s.r_rad - J * p).cwiseAbs().maxCoeff() > 5.0 * std::sqrt(v)) continue;
      H += J.transpose() * J / v;
      g += J.transpose() * s.r_rad / v;
      count += 1.0;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kN, kN>> eigen(H);
    p.setZero();
    for (int i = 0; i < kN; ++i)
      if (eigen.eigenvalues()(i) > 100.0 * count)
        p += eigen.eigenvectors().col(i) * eigen.eigenvectors().col(i).dot(g) /
             eigen.eigenvalues()(i);
  }
  RateError e;
  for (int c = 0; c < 3; ++c) {
    e.A.col(c) = p.segment<3>(3 * c);
    e.D.col(c) = p.segment<3>(9 + 3 * c);
  }
  return e;
}

/// The readings with the bias removed and the rate error M undone: M^-1 (omega - b).
std::vector<GyroReading> corrected(const GyroNoiseInput& in, const Eigen::Matrix3d& M) {
  const Eigen::Matrix3d M_inv = M.inverse();
  std::vector<GyroReading> gyro = in.gyro;
  for (GyroReading& g : gyro) g.omega_body_radps = M_inv * (g.omega_body_radps - in.bias_radps);
  return gyro;
}

/// The residuals once the rate errors are found and taken out: A is folded into the readings'
/// M (omega_measured = M omega) three times, so that the large rotations of the longest lags,
/// where first order is not enough, end up with none left; D, which is not the gyro's, is
/// subtracted from the last residuals.
std::vector<Sample> residualsWithoutRateError(const GyroNoiseInput& in, Eigen::Matrix3d& M,
                                              Eigen::Matrix3d& D) {
  M = Eigen::Matrix3d::Identity();
  std::vector<Sample> samples = residuals(in, corrected(in, M), in.offset_s);
  for (int round = 0; round < 3; ++round) {
    const RateError step = fitRateError(samples, lagVariances(samples, -1, {}));
    M = M * (Eigen::Matrix3d::Identity() + step.A);
    samples = residuals(in, corrected(in, M), in.offset_s);
  }
  const RateError last = fitRateError(samples, lagVariances(samples, -1, {}));
  for (Sample& s : samples) s.r_rad -= last.of(s);
  M = M * (Eigen::Matrix3d::Identity() + last.A);
  D = last.D;
  return samples;
}

struct Fit {
  Vector3d p = Vector3d::Zero();  ///< c, N^2, B^2 of (1)
  double n2_variance = 0.0;       ///< variance of N^2
};

/// Weighted non-negative least squares of (1) over the lags: every subset of the three
/// parameters is solved, the feasible one with the least cost kept. A lag's variance estimate
/// has variance 2 v^2 / (3 n_eff) for 3 axes and n_eff = n / lag independent windows, times
/// 2.7 for the MAD's efficiency (37 % of the sample variance's); v is the model's (after a first
/// fit with the observed).
Fit fitModel(const std::vector<LagVariance>& lags) {
  const int n = static_cast<int>(lags.size());
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd y(n), weight(n);
  for (int k = 0; k < n; ++k) {
    const double tau = lags[k].tau_s;
    A.row(k) << 1.0, tau, tau * tau;
    y(k) = lags[k].variance_rad2;
  }
  Fit best;
  Eigen::VectorXd model = y;
  for (int round = 0; round < 2; ++round) {
    for (int k = 0; k < n; ++k) {
      const double n_eff = std::max(1.0, double(lags[k].samples) / lags[k].lag_scans);
      const double v = std::max(model(k), 1e-300);
      weight(k) = 1.0 / (2.7 * 2.0 * v * v / (3.0 * n_eff));
    }
    double best_cost = std::numeric_limits<double>::infinity();
    for (int subset = 1; subset < 8; ++subset) {
      std::vector<int> cols;
      for (int c = 0; c < 3; ++c)
        if (subset & (1 << c)) cols.push_back(c);
      Eigen::MatrixXd As(n, cols.size());
      for (std::size_t c = 0; c < cols.size(); ++c) As.col(c) = A.col(cols[c]);
      const Eigen::MatrixXd H = As.transpose() * weight.asDiagonal() * As;
      const Eigen::VectorXd x = H.ldlt().solve(As.transpose() * weight.asDiagonal() * y);
      if ((x.array() < 0.0).any() || !x.allFinite()) continue;
      const Eigen::VectorXd e = As * x - y;
      const double cost = e.dot(weight.asDiagonal() * e);
      if (cost >= best_cost) continue;
      best_cost = cost;
      best = Fit{};
      for (std::size_t c = 0; c < cols.size(); ++c) best.p(cols[c]) = x(c);
      // The lags share their data, so the weights overstate the information: the variance is
      // scaled by the reduced chi^2 when that exceeds one.
      const double dof = std::max(1, n - static_cast<int>(cols.size()));
      const Eigen::MatrixXd cov = H.inverse() * std::max(1.0, cost / dof);
      const auto it = std::find(cols.begin(), cols.end(), 1);
      best.n2_variance = it == cols.end() ? cov.trace() : cov(it - cols.begin(), it - cols.begin());
    }
    model = A * best.p;
  }
  return best;
}

double density(const Fit& f) { return std::sqrt(f.p(1)); }

/// 1-sigma of N from that of N^2 (delta method), or the square root of the latter when N^2 is
/// zero or within its own 1-sigma.
double densitySigma(const Fit& f) {
  const double s2 = std::sqrt(f.n2_variance);
  return f.p(1) > s2 ? s2 / (2.0 * density(f)) : std::sqrt(s2);
}

std::string scientific(double v) { return fmt::format("{:.2g}", v); }

}  // namespace

GyroNoiseEstimate estimateGyroNoise(const GyroNoiseInput& input) {
  if (input.gyro.empty()) throw InputError("no gyro readings");
  Eigen::Matrix3d M, D;
  const std::vector<Sample> samples = residualsWithoutRateError(input, M, D);
  std::vector<LagVariance> lags = lagVariances(samples, -1, {});
  if (lags.size() < kMinLags)
    throw InputError(fmt::format(
        "too few registered scans in a row for the gyro's noise ({} lags with {} samples, "
        "{} needed)",
        lags.size(), kMinSamplesPerLag, kMinLags));
  const Fit fit = fitModel(lags);

  // Jackknife over blocks of the stretch: errors correlated over seconds widen it.
  std::vector<double> starts;
  for (const Sample& s : samples) starts.push_back(s.t_s);
  std::vector<double> edges;
  for (int b = 0; b <= kJackknifeBlocks; ++b)
    edges.push_back(percentile(starts, 100.0 * b / kJackknifeBlocks));
  edges.back() += 1.0;  // the last block includes the latest start
  std::vector<double> leave_one_out;
  for (int b = 0; b < kJackknifeBlocks; ++b) {
    const std::vector<LagVariance> part = lagVariances(samples, b, edges);
    if (part.size() >= kMinLags) leave_one_out.push_back(density(fitModel(part)));
  }
  double jackknife_sigma = 0.0;
  if (leave_one_out.size() >= 3) {
    double mean = 0.0;
    for (double d : leave_one_out) mean += d / leave_one_out.size();
    double sum = 0.0;
    for (double d : leave_one_out) sum += (d - mean) * (d - mean);
    const double m = static_cast<double>(leave_one_out.size());
    jackknife_sigma = std::sqrt((m - 1.0) / m * sum);
  }

  GyroNoiseEstimate e;
  e.density_radps_sqrthz = density(fit);
  e.density_sigma = std::max(densitySigma(fit), jackknife_sigma);
  e.rate_error_radps = std::sqrt(fit.p(2));
  e.rate_error_matrix = M - Eigen::Matrix3d::Identity();
  e.rate_change_matrix_s = D;
  e.registration_sigma_rad = std::sqrt(fit.p(0) / 2.0);
  for (LagVariance& l : lags)
    l.model_rad2 = fit.p(0) + fit.p(1) * l.tau_s + fit.p(2) * l.tau_s * l.tau_s;
  e.lags = std::move(lags);
  return e;
}

NoiseVerdict judgeGyroNoise(const GyroNoiseEstimate& e, double configured) {
  NoiseVerdict v;
  const double measured = e.density_radps_sqrthz, sigma = e.density_sigma;
  const std::string figures =
      fmt::format("measured {} +- {} rad/s/sqrt(Hz), configured {}", scientific(measured),
                  scientific(sigma), scientific(configured));
  if (sigma > measured / 3.0) {
    v.text = "gyro noise density not determined by the motion (" + figures + ")";
    return v;
  }
  // Two significant digits, rounded up: a filter is safer a little pessimistic.
  const double scale = std::pow(10.0, std::floor(std::log10(measured)) - 1.0);
  const double suggested = std::ceil(measured / scale) * scale;
  if (configured < measured / 1.5 && configured < measured - 2.0 * sigma) {
    v.kind = NoiseVerdict::Kind::kUnderstated;
    v.suggested = suggested;
    v.text = fmt::format(
        "gyro noise density understated {:.1f}x ({}): set odometry.imu.gyro_noise_density: {}",
        measured / configured, figures, scientific(suggested));
  } else if (configured > 1.5 * measured && configured > measured + 2.0 * sigma) {
    v.kind = NoiseVerdict::Kind::kOverstated;
    v.suggested = suggested;
    v.text = fmt::format(
        "gyro noise density overstated {:.1f}x ({}): odometry.imu.gyro_noise_density: {} would "
        "fit",
        configured / measured, figures, scientific(suggested));
  } else {
    v.kind = NoiseVerdict::Kind::kConsistent;
    v.text = "gyro noise density consistent (" + figures + ")";
  }
  return v;
}

const char* toString(NoiseVerdict::Kind kind) {
  switch (kind) {
    case NoiseVerdict::Kind::kConsistent:
      return "consistent";
    case NoiseVerdict::Kind::kUnderstated:
      return "understated";
    case NoiseVerdict::Kind::kOverstated:
      return "overstated";
    case NoiseVerdict::Kind::kUndetermined:
      return "undetermined";
  }
  return "undetermined";
}

}  // namespace taiga::calib
