#pragma once
// The error model of GNSS fixes under canopy, and the fit that uses it (issue 23;
// docs/georeferencing.md, "Correlated GNSS errors").
//
// A fix's error, normalized by its reported 1-sigma s_k, is a unit first-order Gauss-Markov
// process plus white noise:
//   e_k / s_k = m(t_k) + v_k,   E[m(t) m(t')] = exp(-|t - t'| / tau),   v_k ~ N(0, q).
// m is the slowly drifting error under canopy (multipath, satellites coming and going), v what
// changes from fix to fix. A scalar Kalman filter over m gives the innovations, independent with
// known variance; dividing each by its standard deviation whitens the residuals and, applied to
// the Jacobian's columns too, turns least squares into generalized least squares (the best
// linear unbiased estimate under the model), whose normal matrix is the model's information (the
// inverse of the Cramer-Rao bound of the linearized fit).
// The whitened residuals' spread is then the honest scale of the reported sigmas, which plain
// residuals hide when the errors drift slowly.
//
// The reported sigma is an estimate too, so the model believes only a share of its swings from
// their mean (sigma_trust): a model that takes every swing at its word reads the offset from
// the swings and becomes far too sure of itself when they are partly noise (an errors-in-
// variables effect that no white noise term absorbs). tau, q and that share are not known for a
// receiver: the fit takes the most likely of a few candidates around the configured tau.

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <vector>

namespace taiga::georef {

/// What the fit found out about the error model (georef.yaml's `error_model`).
struct GnssErrorModel {
  double configured_correlation_time_s = 0.0;
  double correlation_time_s = 0.0;  ///< tau chosen: the configured one or 3x (0: white noise)
  /// Variance of the white part, in units of the Gauss-Markov part's (q above).
  double white_share = 0.0;
  /// How far the reported sigmas' swings are believed: the model's sigma of fix k is
  /// exp(trust log s_k + (1 - trust) log mean_k), mean_k the geometric mean of the reported
  /// sigmas within sigma_mean_window_s / 2 of the fix (infinite: the whole walk). 1: as reported.
  double sigma_trust = 1.0;
  double sigma_mean_window_s = std::numeric_limits<double>::infinity();
  /// The whitened residuals' RMS: the factor by which the reported sigmas are too small (> 1)
  /// or too large (< 1), horizontally and vertically.
  double sigma_scale_horizontal = 1.0;
  double sigma_scale_up = 1.0;
  /// How many independent fixes the model's information about a constant offset is worth (the
  /// number of fixes for white noise, about 2 + T / (2 tau) for fixes dense over T >> tau).
  double independent_fixes = 0.0;
  /// Lag-one correlation of the whitened horizontal residuals (east and north averaged): near 0
  /// when the model fits, positive when the errors stay correlated longer than it says.
  double whitened_lag_one_correlation = 0.0;
};

/// The generalized least-squares fit of the robust method's parameters (yaw, horizontal offset,
/// height offset of T_enu_world; roll = pitch = 0).
struct GaussMarkovFit {
  double yaw_rad = 0.0;
  Eigen::Vector2d t = Eigen::Vector2d::Zero();  ///< east, north of the world origin, m
  double t_up = 0.0;                            ///< m
  /// Over (t_east, t_north, yaw), m^2 and rad^2: the model's information inverted and scaled
  /// by sigma_scale_horizontal^2; up_variance likewise with sigma_scale_up^2.
  Eigen::Matrix3d horizontal_covariance = Eigen::Matrix3d::Zero();
  double up_variance = 0.0;
  GnssErrorModel model;
  std::vector<bool> used;  ///< per pair: the fit used it
};

struct AssociatedFix;

struct GaussMarkovOptions {
  double correlation_time_s = 30.0;  ///< the configured tau, s (0: white noise)
  /// Fixes whose whitened residual exceeds this many robust sigmas are dropped (multipath).
  double outlier_sigmas = 4.0;
  /// Use this model instead of choosing the most likely (a previous choice).
  std::optional<GnssErrorModel> model;
};

/// The fixes with use[i] (at least 3 at distinct times, else InputError) are taken in time
/// order; a fix at the same time as the previous one is skipped. For each candidate model
/// (correlation time tau or 3 tau, or white noise when tau is 0; white share; sigma trust; or
/// only options.model), Gauss-Newton from (start_yaw_rad, start_t) over
/// (t_east, t_north, yaw) and the height offset in closed form; the most likely is returned.
/// Then fixes whose whitened residual exceeds outlier_sigmas robust sigmas (multipath that
/// plain residuals hide) are dropped one at a time, at most a fifth of them.
GaussMarkovFit fitGaussMarkov(const std::vector<AssociatedFix>& pairs, const std::vector<bool>& use,
                              double start_yaw_rad, const Eigen::Vector2d& start_t,
                              const GaussMarkovOptions& options);

}  // namespace taiga::georef
