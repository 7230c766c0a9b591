#pragma once
// The lidar-IMU time offset and extrinsic rotation from rotation increments (docs/calibration.md).
//
// The lidar's registration gives the body's rotation between consecutive scans, ΔR_reg, in the
// body frame the configured rig defines (R_body_lidar_cfg). The gyro gives the same rotation in the
// true body frame, on the IMU's clock. For any increment (hand-eye calibration on SO(3)):
//   Log(ΔR_gyro[t0 + dt, t1 + dt] with bias b) = R_c * Log(ΔR_reg[t0, t1])
// because conjugating a rotation rotates its rotation vector. R_c = R_body_lidar_true *
// R_body_lidar_cfg^T is the rig's rotation error and dt the time offset still missing from
// rig.lidar_time_offset_s. The rotation-vector residual
//   r_k = Log(ΔR_gyro,k(dt, b)) - R_c Log(ΔR_reg,k)                                    (1)
// is minimized over (R_c, b) in closed form for each dt on a grid (a profile cost, its curve is
// the report's plot), then over (dt, R_c, b) together by Gauss-Newton. The reported variances
// are the largest of three: the fit's own, a lag-2 Newey-West estimate (consecutive increments
// share a registration, so their errors are correlated), and a jackknife over six blocks of the
// stretch (errors correlated over seconds, a drifting clock).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "taiga/lie/so3.hpp"

namespace taiga::calib {

/// The body's rotation from t0_s to t1_s as the lidar registration saw it: Log(R_0^T R_1), in the
/// configured body frame. Times are the odometry's (lidar clock + configured offset).
struct RotationIncrement {
  double t0_s = 0.0, t1_s = 0.0;
  Eigen::Vector3d theta_body_rad = Eigen::Vector3d::Zero();
};

/// A gyro reading rotated into the body frame (R_body_imu * omega_imu), on the IMU's clock.
struct GyroReading {
  double t_s = 0.0;
  Eigen::Vector3d omega_body_radps = Eigen::Vector3d::Zero();
};

struct TimeRotationOptions {
  double max_offset_s = 0.2;   ///< the grid spans +-max_offset_s around the configured offset
  double grid_step_s = 0.001;  ///< grid spacing of the profile cost
  /// A quantity whose 1-sigma exceeds these is not observable from the motion, unless its change
  /// is significant (at least 3 sigma) and its 1-sigma within ten times these: held at its
  /// configured value (rotation: per direction of the information's eigenvectors).
  double max_offset_sigma_s = 0.002;
  double max_rotation_sigma_rad = 0.002;  // 0.11 deg
  /// Residuals beyond this many robust sigmas (1.4826 MAD) are dropped (failed registrations).
  double outlier_sigmas = 5.0;
};

struct CostPoint {
  double offset_s = 0.0;
  double rms_radps = 0.0;  ///< RMS of residual (1) over the increments' durations at this offset
};

struct TimeRotationEstimate {
  /// Add to rig.lidar_time_offset_s (0 when not observable).
  double offset_s = 0.0;
  double offset_sigma_s = 0.0;
  bool offset_observable = false;
  /// R_body_lidar_true = R_correction * R_body_lidar_cfg (identity in the directions not
  /// observable).
  lie::SO3 R_correction;
  /// 1-sigma of the correction's rotation vector about the body x, y, z axes, rad.
  Eigen::Vector3d rotation_sigma_rad = Eigen::Vector3d::Zero();
  /// The body axes (x, y, z) about which the rotation could be estimated. An axis counts as
  /// observable when every information direction with a share of it above 1/3 was.
  Eigen::Vector3<bool> rotation_observable{false, false, false};
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
  double residual_rms_radps = 0.0;
  /// RMS of the rate the registration saw (|R_c l| over each increment's duration): the signal
  /// the residual is to be compared with.
  double signal_rms_radps = 0.0;
  std::size_t increments_used = 0, increments_dropped = 0;
  std::vector<CostPoint> cost_curve;
  /// What motion would make the unobservable quantities observable; empty when all were.
  std::string advice;
};

/// The body axes still observable when the directions `held` were not: an axis is lost when a
/// held direction leans on it by more than 1/3 of its square (for the rotation and the lever arm).
Eigen::Vector3<bool> axesNotHeld(const std::vector<Eigen::Vector3d>& held);

/// The names of the axes set in `which`, e.g. "xz"; empty when none.
std::string axisNames(const Eigen::Vector3<bool>& which);
/// axisNames, or "none" (for the terminal).
std::string axisNamesOrNone(const Eigen::Vector3<bool>& which);

/// Throws InputError when fewer than 20 increments or no gyro readings overlap them.
TimeRotationEstimate estimateTimeRotation(const std::vector<RotationIncrement>& increments,
                                          const std::vector<GyroReading>& gyro,
                                          const TimeRotationOptions& options = {});

/// The gyro's rotation over [t0_s, t1_s] with `bias` removed, the readings linear between their
/// stamps as in the odometry (imu/readings.hpp). Readings must be sorted by time and cover the
/// interval.
lie::SO3 integrateGyro(const std::vector<GyroReading>& gyro, double t0_s, double t1_s,
                       const Eigen::Vector3d& bias_radps);

}  // namespace taiga::calib
