#pragma once
// The gyro's white-noise density measured against the lidar (docs/calibration.md, "IMU noise").
//
// Over a lag of tau seconds between two registered scans, the gyro's integrated rotation and the
// registrations' differ by
//   r(tau) = Log((R_c ΔR_reg(t, t + tau) R_c^T)^T ΔR_gyro(t + dt, t + tau + dt; b))
// (R_c, dt, b: the rotation, offset and bias of calib::estimateTimeRotation). Its variance per
// axis grows with the lag as
//   v(tau) = c + N^2 tau + B^2 tau^2                                                     (1)
// c: the two registrations' own noise, constant in the lag; N^2 tau: the gyro's angle random walk
// (white rate noise of density N integrates to a variance N^2 tau, the slope of an Allan
// variance); B^2 tau^2: a rate error that stays over the lag, the bias's departure from the
// stretch's constant estimate (B, rad/s RMS). Fitting (1) over lags of 0.1 to a few seconds
// separates them, because the registrations' noise does not grow with the lag while the gyro's
// does. The lidar is the reference, so this is an Allan analysis in motion, without a static
// hour on a table. Before (1), the residual's parts proportional to the rotation (the gyro's
// scale and axis errors, A) and to the change of the rate over the lag (a leftover time offset,
// D) are fitted and taken out (gyro_noise.cpp): they too grow with the lag.
//
// The accelerometer's density is not measured: over the lags the registrations resolve, its
// white noise moves the body by less than a millimetre, far below their noise.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "taiga/calib/time_rotation.hpp"
#include "taiga/core/trajectory.hpp"

namespace taiga::calib {

struct GyroNoiseInput {
  /// Chains of consecutive registered body poses T_odom_body (a chain breaks where a scan was
  /// not registered); times are the odometry's.
  std::vector<std::vector<StampedPose>> chains;
  std::vector<GyroReading> gyro;  ///< body frame, IMU clock, sorted by time
  double offset_s = 0.0;          ///< add to the poses' times for the IMU's clock
  lie::SO3 R_correction;          ///< registration body frame -> gyro body frame (R_c)
  Eigen::Vector3d bias_radps = Eigen::Vector3d::Zero();
};

/// The residual's variance at one lag (a point of the report's plot).
struct LagVariance {
  int lag_scans = 0;
  double tau_s = 0.0;          ///< mean lag
  double variance_rad2 = 0.0;  ///< per axis (robust: 1.4826 MAD, squared, mean of the axes)
  double model_rad2 = 0.0;     ///< (1) at tau_s with the fitted parameters
  std::size_t samples = 0;
};

struct GyroNoiseEstimate {
  double density_radps_sqrthz = 0.0;    ///< N
  double density_sigma = 0.0;           ///< its 1-sigma (the fit's or a block jackknife's, larger)
  double rate_error_radps = 0.0;        ///< B
  double registration_sigma_rad = 0.0;  ///< sqrt(c / 2): one registration's rotation noise
  /// The gyro's rate error found and undone before (1): omega_measured = (I + this) omega, its
  /// diagonal the scale-factor errors (0.005 for 0.5 %), the rest axis misalignment (a rotation
  /// of the lidar is in R_c, not here). It also holds any scale error of the registrations.
  Eigen::Matrix3d rate_error_matrix = Eigen::Matrix3d::Zero();
  /// The residual's part that follows the rate's change over the lag, r ~ D (omega(t_end) -
  /// omega(t_start)), taken out before (1) too: a time offset the rotation calibration left
  /// (D = -dt I) and the deskew errors of a gyro's scale errors, s.
  Eigen::Matrix3d rate_change_matrix_s = Eigen::Matrix3d::Zero();
  std::vector<LagVariance> lags;
};

/// Throws InputError when the chains give fewer than 4 lags with 30 samples each.
GyroNoiseEstimate estimateGyroNoise(const GyroNoiseInput& input);

/// What the measured density says of the configured one.
struct NoiseVerdict {
  enum class Kind { kConsistent, kUnderstated, kOverstated, kUndetermined };
  Kind kind = Kind::kUndetermined;
  double suggested = 0.0;  ///< the measured value, rounded up to two digits; 0 when consistent
  std::string text;        ///< one line for the terminal and the report
};

/// Consistent when the configured density lies within a factor 1.5 of the measured one or
/// within its 2-sigma; undetermined when the measurement's 1-sigma exceeds a third of it.
NoiseVerdict judgeGyroNoise(const GyroNoiseEstimate& estimate, double configured_radps_sqrthz);

const char* toString(NoiseVerdict::Kind kind);

}  // namespace taiga::calib
