#include "taiga/georef/gauss_markov.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "taiga/core/errors.hpp"
#include "taiga/georef/association.hpp"

namespace taiga::georef {
namespace {

/// The used fixes in time order, one per time.
std::vector<std::size_t> timeOrder(const std::vector<AssociatedFix>& pairs,
                                   const std::vector<bool>& use) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < pairs.size(); ++i)
    if (use[i]) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return pairs[a].fix.t_s < pairs[b].fix.t_s;
  });
  order.erase(std::unique(order.begin(), order.end(),
                          [&](std::size_t a, std::size_t b) {
                            return pairs[a].fix.t_s == pairs[b].fix.t_s;
                          }),
              order.end());
  return order;
}

/// The fixes' data in time order. sigma_h is the root of the mean of the east and north variances.
struct Series {
  std::vector<double> t_s, sigma_h, sigma_up;
  std::vector<Eigen::Vector2d> a_world, b_enu;  // horizontal antenna (world) and fix (ENU)
  std::vector<double> d_up;                     // fix up - antenna z
};

Series seriesOf(const std::vector<AssociatedFix>& pairs, const std::vector<std::size_t>& order) {
  Series series;
  for (std::size_t i : order) {
    const AssociatedFix& pair = pairs[i];
    const Eigen::Matrix3d& covariance = pair.fix.covariance_enu_m2;
    series.t_s.push_back(pair.fix.t_s);
    series.sigma_h.push_back(std::sqrt(0.5 * (covariance(0, 0) + covariance(1, 1))));
    series.sigma_up.push_back(std::sqrt(covariance(2, 2)));
    series.a_world.push_back(pair.p_world.head<2>());
    series.b_enu.push_back(pair.fix.p_enu.head<2>());
    series.d_up.push_back(pair.fix.p_enu.z() - pair.p_world.z());
  }
  return series;
}

/// The sigmas the model uses: exp(trust log s_k + (1 - trust) log mean_k), mean_k the geometric
/// mean of the reported sigmas within window_s / 2 of fix k (infinite: the whole walk's).
/// trust 1: as reported; 0: only their mean over the window.
std::vector<double> modelSigma(const std::vector<double>& t_s, const std::vector<double>& sigma,
                               double trust, double window_s) {
  if (trust >= 1.0) return sigma;
  std::vector<double> prefix(sigma.size() + 1, 0.0);  // sums of log sigma
  for (std::size_t k = 0; k < sigma.size(); ++k) prefix[k + 1] = prefix[k] + std::log(sigma[k]);
  std::vector<double> out(sigma.size());
  std::size_t begin = 0, end = 0;
  for (std::size_t k = 0; k < sigma.size(); ++k) {
    while (t_s[k] - t_s[begin] > 0.5 * window_s) ++begin;
    while (end < sigma.size() && t_s[end] - t_s[k] <= 0.5 * window_s) ++end;
    const double log_mean = (prefix[end] - prefix[begin]) / static_cast<double>(end - begin);
    out[k] = std::exp(trust * std::log(sigma[k]) + (1.0 - trust) * log_mean);
  }
  return out;
}

/// The scalar Kalman filter over the unit Gauss-Markov state m observed with white noise of
/// variance q (header). Its gains do not depend on the data, so one pass of whiten() per
/// sequence (the residuals, each column of the Jacobian) applies the same linear map to all.
class Whitener {
 public:
  Whitener(const std::vector<double>& t_s, double tau_s, double white_share) {
    double P = 1.0;  // the state's variance after the previous update
    for (std::size_t k = 0; k < t_s.size(); ++k) {
      Step step;
      step.phi = k > 0 && tau_s > 0.0 ? std::exp(-(t_s[k] - t_s[k - 1]) / tau_s) : 0.0;
      const double P_predicted =
          k == 0 ? 1.0 : step.phi * step.phi * P + (1.0 - step.phi * step.phi);
      const double S = P_predicted + white_share;  // the innovation's variance
      step.inv_sqrt_s = 1.0 / std::sqrt(S);
      step.gain = P_predicted / S;
      P = (1.0 - step.gain) * P_predicted;
      log_determinant_ += std::log(S);
      steps_.push_back(step);
    }
  }

  /// The whitened innovation of the k-th value of a sequence whose filter state is `state`.
  template <class T>
  T whiten(std::size_t k, const T& value, T& state) const {
    const Step& step = steps_[k];
    const T innovation = value - step.phi * state;
    state = step.phi * state + step.gain * innovation;
    return step.inv_sqrt_s * innovation;
  }

  /// sum log S_k: the model's log-determinant for one unit-scaled series.
  double logDeterminant() const { return log_determinant_; }
  std::size_t size() const { return steps_.size(); }

 private:
  struct Step {
    double phi = 0.0, inv_sqrt_s = 1.0, gain = 0.0;
  };
  std::vector<Step> steps_;
  double log_determinant_ = 0.0;
};

double lagOneCorrelation(const std::vector<double>& values) {
  if (values.size() < 3) return 0.0;
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= static_cast<double>(values.size());
  double lag = 0.0, variance = 0.0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    variance += (values[k] - mean) * (values[k] - mean);
    if (k > 0) lag += (values[k] - mean) * (values[k - 1] - mean);
  }
  return variance > 0.0 ? lag / variance : 0.0;
}

struct HorizontalSystem {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // whitened J^T J
  Eigen::Vector3d g = Eigen::Vector3d::Zero();  // whitened J^T w
  double rss = 0.0;
  std::vector<double> east, north;  // whitened residuals
};

/// The whitened normal equations of the horizontal fit at (yaw, t): residuals
/// r = R(yaw) a + t - b normalized by sigma.
HorizontalSystem horizontalSystem(const Series& series, const std::vector<double>& sigma,
                                  const Whitener& whitener, double yaw_rad,
                                  const Eigen::Vector2d& t) {
  HorizontalSystem system;
  const Eigen::Rotation2Dd R(yaw_rad);
  Eigen::Vector2d residual_state = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, 3> jacobian_state = Eigen::Matrix<double, 2, 3>::Zero();
  for (std::size_t k = 0; k < sigma.size(); ++k) {
    const Eigen::Vector2d Ra = R * series.a_world[k];
    Eigen::Matrix<double, 2, 3> J;
    J << 1.0, 0.0, -Ra.y(),  //
        0.0, 1.0, Ra.x();
    const Eigen::Vector2d w =
        whitener.whiten<Eigen::Vector2d>(k, (Ra + t - series.b_enu[k]) / sigma[k], residual_state);
    const Eigen::Matrix<double, 2, 3> Jw =
        whitener.whiten<Eigen::Matrix<double, 2, 3>>(k, J / sigma[k], jacobian_state);
    system.H += Jw.transpose() * Jw;
    system.g += Jw.transpose() * w;
    system.rss += w.squaredNorm();
    system.east.push_back(w.x());
    system.north.push_back(w.y());
  }
  return system;
}

struct Candidate {
  GaussMarkovFit fit;
  /// Gaussian log-likelihood with the scales concentrated out, per series:
  /// -m/2 log(rss / m) - 1/2 sum log S_k - sum log sigma_k.
  double log_likelihood = 0.0;
  /// Per fix in time order: its whitened residual in robust sigmas, the larger of the
  /// horizontal (norm) and the vertical one. A jump of the error (multipath) stands out here
  /// many times more than in the plain residuals: the model expects the error to change slowly.
  std::vector<double> outlyingness;
};

double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

double sumOfLogs(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += std::log(v);
  return sum;
}

Candidate fitCandidate(const Series& series, const GnssErrorModel& model, double start_yaw_rad,
                       const Eigen::Vector2d& start_t) {
  const Whitener whitener(series.t_s, model.correlation_time_s, model.white_share);
  const std::vector<double> sigma_h =
      modelSigma(series.t_s, series.sigma_h, model.sigma_trust, model.sigma_mean_window_s);
  const std::vector<double> sigma_up =
      modelSigma(series.t_s, series.sigma_up, model.sigma_trust, model.sigma_mean_window_s);
  const double m = static_cast<double>(series.t_s.size());

  Candidate candidate;
  GaussMarkovFit& fit = candidate.fit;
  fit.model = model;
  fit.yaw_rad = start_yaw_rad;
  fit.t = start_t;
  HorizontalSystem system = horizontalSystem(series, sigma_h, whitener, fit.yaw_rad, fit.t);
  constexpr int kMaxIterations = 20;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    const Eigen::Vector3d delta = -system.H.ldlt().solve(system.g);
    fit.t += delta.head<2>();
    fit.yaw_rad += delta.z();
    system = horizontalSystem(series, sigma_h, whitener, fit.yaw_rad, fit.t);
    if (delta.head<2>().norm() < 1e-9 && std::abs(delta.z()) < 1e-12) break;
  }
  const double scale2_h = system.rss / std::max(1.0, 2.0 * m - 3.0);
  fit.horizontal_covariance = scale2_h * system.H.ldlt().solve(Eigen::Matrix3d::Identity());

  // Height offset: d = up - z_world = t_up + e, normalized and whitened; linear. The constant
  // column whitened with unit sigmas gives the independent fixes.
  double xx = 0.0, xy = 0.0, yy = 0.0, ones = 0.0;
  double x_state = 0.0, y_state = 0.0, one_state = 0.0;
  std::vector<double> xw(sigma_up.size()), yw(sigma_up.size());
  for (std::size_t k = 0; k < sigma_up.size(); ++k) {
    xw[k] = whitener.whiten(k, 1.0 / sigma_up[k], x_state);
    yw[k] = whitener.whiten(k, series.d_up[k] / sigma_up[k], y_state);
    const double one = whitener.whiten(k, 1.0, one_state);
    xx += xw[k] * xw[k];
    xy += xw[k] * yw[k];
    yy += yw[k] * yw[k];
    ones += one * one;
  }
  fit.t_up = xy / xx;
  const double rss_up = std::max(0.0, yy - xy * xy / xx);
  const double scale2_up = rss_up / std::max(1.0, m - 1.0);
  fit.up_variance = scale2_up / xx;

  constexpr double kTiny = 1e-300;  // exact data
  candidate.log_likelihood = -m * std::log(std::max(system.rss / (2.0 * m), kTiny)) -
                             whitener.logDeterminant() - 2.0 * sumOfLogs(sigma_h) -
                             0.5 * m * std::log(std::max(rss_up / m, kTiny)) -
                             0.5 * whitener.logDeterminant() - sumOfLogs(sigma_up);

  fit.model.sigma_scale_horizontal = std::sqrt(scale2_h);
  fit.model.sigma_scale_up = std::sqrt(scale2_up);
  fit.model.independent_fixes = ones * (1.0 + model.white_share);
  fit.model.whitened_lag_one_correlation =
      0.5 * (lagOneCorrelation(system.east) + lagOneCorrelation(system.north));

  constexpr double kRayleighMedian = 1.1774100225154747;  // median norm of a 2D unit Gaussian
  constexpr double kMadToSigma = 1.482602218505602;
  std::vector<double> norm_h(sigma_h.size()), abs_up(sigma_up.size());
  for (std::size_t k = 0; k < sigma_h.size(); ++k) {
    norm_h[k] = std::hypot(system.east[k], system.north[k]);
    abs_up[k] = std::abs(yw[k] - xw[k] * fit.t_up);
  }
  const double scale_h = std::max(median(norm_h) / kRayleighMedian, 1e-12);
  const double scale_up = std::max(kMadToSigma * median(abs_up), 1e-12);
  for (std::size_t k = 0; k < sigma_h.size(); ++k)
    candidate.outlyingness.push_back(std::max(norm_h[k] / scale_h, abs_up[k] / scale_up));
  return candidate;
}

/// The most likely of the candidate models (header) for the fixes of `series`.
Candidate mostLikely(const Series& series, const GaussMarkovOptions& options, double start_yaw_rad,
                     const Eigen::Vector2d& start_t) {
  if (options.model) return fitCandidate(series, *options.model, start_yaw_rad, start_t);
  const double tau_s = options.correlation_time_s;
  // Not shorter than the configured correlation time: a misfit of the model (the reported
  // sigmas' own noise) looks like errors that decorrelate faster, and a shorter tau would make
  // the fit surer of itself (tried: tau / 3 was chosen on a quarter of the noisiest walks, with
  // 2-4 sigma errors).
  const std::vector<double> taus =
      tau_s > 0.0 ? std::vector<double>{tau_s, 3.0 * tau_s} : std::vector<double>{0.0};
  const std::vector<double> white_shares =
      tau_s > 0.0 ? std::vector<double>{0.0, 0.03, 0.1, 0.3} : std::vector<double>{0.0};
  constexpr double kWholeWalk = std::numeric_limits<double>::infinity();
  std::vector<std::pair<double, double>> trusts{{1.0, kWholeWalk}};  // (trust, mean window)
  for (double window_s : {kWholeWalk, 30.0})
    for (double trust : {0.9, 0.75, 0.5, 0.25, 0.0}) trusts.emplace_back(trust, window_s);
  std::optional<Candidate> best;
  for (double tau : taus) {
    for (double white_share : white_shares) {
      for (const auto& [trust, window_s] : trusts) {
        const GnssErrorModel model{.configured_correlation_time_s = tau_s,
                                   .correlation_time_s = tau,
                                   .white_share = white_share,
                                   .sigma_trust = trust,
                                   .sigma_mean_window_s = window_s};
        Candidate candidate = fitCandidate(series, model, start_yaw_rad, start_t);
        if (!best || candidate.log_likelihood > best->log_likelihood + 1e-9)
          best = std::move(candidate);
      }
    }
  }
  return std::move(*best);
}

}  // namespace

GaussMarkovFit fitGaussMarkov(const std::vector<AssociatedFix>& pairs, const std::vector<bool>& use,
                              double start_yaw_rad, const Eigen::Vector2d& start_t,
                              const GaussMarkovOptions& options) {
  std::vector<std::size_t> order = timeOrder(pairs, use);
  if (order.size() < 3)
    throw InputError(
        fmt::format("georef: {} fixes at distinct times, at least 3 are needed", order.size()));
  Candidate best = mostLikely(seriesOf(pairs, order), options, start_yaw_rad, start_t);
  // Multipath the first (plain-residual) screening left: the most outlying fix under the model
  // is dropped and the fit redone, one at a time, at most a fifth of the fixes; then the model
  // is chosen again without them.
  std::size_t dropped = 0;
  while (dropped < order.size() / 5 && order.size() > 3) {
    const auto worst = std::max_element(best.outlyingness.begin(), best.outlyingness.end());
    if (*worst <= options.outlier_sigmas) break;
    order.erase(order.begin() + (worst - best.outlyingness.begin()));
    ++dropped;
    best = fitCandidate(seriesOf(pairs, order), best.fit.model, best.fit.yaw_rad, best.fit.t);
  }
  if (dropped > 0) best = mostLikely(seriesOf(pairs, order), options, best.fit.yaw_rad, best.fit.t);
  best.fit.used.assign(pairs.size(), false);
  for (std::size_t i : order) best.fit.used[i] = true;
  return std::move(best.fit);
}

}  // namespace taiga::georef
