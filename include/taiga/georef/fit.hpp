#pragma once
// Post-fit georeferencing: the rigid transform T_enu_world that takes a finished trajectory's
// world frame (the map, gravity-aligned, z up) into the local ENU frame of the GNSS fixes.
// Pure functions on associated fixes (association.hpp): no I/O. The equations are in
// docs/georeferencing.md; the four methods follow thesis 3.4 and its recommendation:
//
//   closed  rigid Umeyama/Horn fit of the antenna positions, no scale, unweighted.
//   pf3     positions only, Gauss-Newton on 6 DoF, each residual weighted by the combined
//           covariance Sigma_i = Sigma_gnss,i + R Sigma_traj R^T (thesis Eq. 44), re-weighted
//           every iteration; starts from closed.
//   pf6     poses: positions and the IMU's absolute orientation, residual
//           Log(T_meas^-1 * T_enu_world * T_world_body) on SE(3), covariance transported with
//           the adjoint (thesis Eq. 47), Gauss-Newton (Eq. 48-52); starts from closed.
//   robust  what the thesis recommends: yaw and the horizontal offset from the horizontal track
//           only (2D rigid fit, Cauchy IRLS, multipath outliers rejected), roll = pitch = 0
//           because the map is gravity-aligned, height offset from a Huber estimate of the
//           height differences.
//
// Uncertainty: the parameters are the ENU position of the world origin (t of T_enu_world) and
// small rotations about the ENU axes (east = roll, north = pitch, up = yaw) applied on the left:
// T_enu_world' = (Exp(dtheta) R, t + dt). `covariance` is over [dt; dtheta]; `sigma` is its
// square-rooted diagonal. Covariances come from the (weighted) normal equations scaled by the
// a-posteriori variance factor (the residuals' own spread; for pf3 and pf6 never below 1,
// so residuals that look better than the reported covariance do not shrink it), so an optimistic
// receiver does not make the fit look better than it is. GNSS errors under canopy are correlated
// over tens of seconds, which closed, pf3 and pf6 ignore: their covariance is then inflated by
// f = (1/m) sum_i sum_j exp(-|t_i - t_j| / tau) over the m fixes used, the variance of the mean of
// m samples of a first-order Gauss-Markov error with correlation time tau relative to white noise
// (f = 1 for tau = 0, f = m when all fixes fall within much less than tau): exact for the
// translation of a fit that is an average, an approximation for the rotations. robust models the
// correlation instead (gauss_markov.hpp): its covariance is the error model's own.

#include <Eigen/Core>
#include <optional>
#include <string_view>
#include <vector>

#include "taiga/georef/association.hpp"
#include "taiga/georef/gauss_markov.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::georef {

enum class GeorefMethod { kClosed, kPf3, kPf6, kRobust };

/// "closed", "pf3", "pf6", "robust".
std::string_view methodName(GeorefMethod method);
/// Inverse of methodName(); InputError naming the accepted values otherwise.
GeorefMethod parseMethod(std::string_view name);

struct FitOptions {
  /// pf3/pf6: 1-sigma of the trajectory's position, isotropic, world frame, m (Sigma_traj).
  double trajectory_position_sigma_m = 0.05;
  /// pf6: 1-sigma of the trajectory's orientation, isotropic, body frame, rad.
  double trajectory_rotation_sigma_rad = 0.002;
  /// pf6: 1-sigma of the IMU's absolute orientation: tilt (about east and north) and heading
  /// (about up), rad. AHRS modules without a magnetometer have an arbitrary heading: then pf6's
  /// yaw is only as good as this sigma claims.
  double orientation_tilt_sigma_rad = 0.0175;     // 1 deg
  double orientation_heading_sigma_rad = 0.0873;  // 5 deg
  /// robust: roll and pitch are zero because the map is gravity-aligned; this is the 1-sigma
  /// reported for them (the map's tilt error is not estimated here), rad.
  double gravity_tilt_sigma_rad = 0.0017;  // 0.1 deg
  /// robust: Cauchy scale of the horizontal residual norm and Huber threshold of the height
  /// differences, in units of the robust residual scale.
  double cauchy_scale = 2.5;
  double huber_threshold = 1.345;
  /// robust: fixes whose normalized residual exceeds this after the robust fit are outliers.
  double outlier_threshold = 4.0;
  /// Correlation time of the GNSS errors, s (0: white noise); see the header comment. 30 s is
  /// typical under canopy (and the simulator's value).
  double error_correlation_time_s = 30.0;
  /// robust: fit with this error model instead of choosing the most likely around
  /// error_correlation_time_s (gauss_markov.hpp); the online estimator between its choices.
  std::optional<GnssErrorModel> error_model;
  int max_iterations = 50;
  /// Gauss-Newton and IRLS stop when the update is below this (m and rad).
  double convergence_step = 1e-9;
  void validate() const;
};

struct GeorefFit {
  GeorefMethod method = GeorefMethod::kRobust;
  lie::SE3 T_enu_world;
  /// Over [dt_east, dt_north, dt_up, dtheta_east (roll), dtheta_north (pitch), dtheta_up (yaw)],
  /// m^2 and rad^2 (see the header comment).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  /// 1-sigma per DoF: east, north, up (m), roll, pitch, yaw (rad).
  Eigen::Matrix<double, 6, 1> sigma = Eigen::Matrix<double, 6, 1>::Zero();
  std::vector<bool> inlier;  ///< per associated fix
  std::size_t inliers = 0;
  std::size_t outliers = 0;
  /// pf6: fixes without an IMU orientation at their time (not used, not outliers).
  std::size_t without_orientation = 0;
  /// Residuals T_enu_world * p_world - p_enu over the inliers, m.
  double residual_rms_m = 0.0;
  /// The covariance inflation f for correlated errors (1: none; robust models them instead).
  double correlation_inflation = 1.0;
  /// robust: the error model of the fixes as the fit found it (gauss_markov.hpp).
  std::optional<GnssErrorModel> error_model;
  double horizontal_rms_m = 0.0;
  double vertical_rms_m = 0.0;
  int iterations = 0;
  bool converged = true;
};

/// Roll, pitch and yaw (rad) of a rotation R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d rollPitchYaw(const lie::SO3& R);

/// Each throws InputError when the fixes cannot determine the transform (fewer than 3 pairs, or
/// all on a line). fitPf6 takes, per associated fix, the IMU's orientation R_enu_body at its
/// time (see orientation.hpp) and throws InputError when fewer than 3 fixes have one.
GeorefFit fitClosed(const std::vector<AssociatedFix>& pairs, const FitOptions& options);
GeorefFit fitPf3(const std::vector<AssociatedFix>& pairs, const FitOptions& options);
GeorefFit fitPf6(const std::vector<AssociatedFix>& pairs,
                 const std::vector<std::optional<lie::SO3>>& R_enu_body,
                 const FitOptions& options);
GeorefFit fitRobust(const std::vector<AssociatedFix>& pairs, const FitOptions& options);

}  // namespace taiga::georef
