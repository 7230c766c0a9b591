#pragma once
// The lidar's lever arm (translation of T_body_lidar) from registered poses and the IMU
// (docs/calibration.md, "Lever arm").
//
// The registration gives the body's pose with the configured lever arm t_cfg: p_k is where the
// body would be if the lidar sat at t_cfg. The true body position is p_k - R_k * d with
// d = t_true - t_cfg. Between consecutive scans the IMU's preintegrated Dp, Dv ([Forster] Eq. 33)
// tie the true positions and velocities together:
//   (R_k - R_k+1) d - v_k dt - R_k dP/dba b_a = p_k - p_k+1 + g dt^2 / 2 + R_k Dp        (2)
//   v_k+1 - v_k - R_k dV/dba b_a                = g dt + R_k Dv
// which is linear in d, the accelerometer bias b_a and the velocities v_k: a least-squares
// problem. Only rotation moves the lever arm (R_k - R_k+1 = 0 without it), so a component is
// observable only where the rig turned about the axes across it; the others are held.

#include <Eigen/Core>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/imu/preintegration.hpp"

namespace taiga::calib {

struct LeverArmInput {
  /// Chains of consecutive registered body poses T_odom_body in a levelled odom frame (gravity
  /// along -z); a chain breaks where a scan was not registered.
  std::vector<std::vector<StampedPose>> chains;
  /// IMU readings in the body frame, sorted by time, covering the chains.
  std::vector<ImuSample> imu_body;
  Eigen::Vector3d gravity_odom_mps2{0.0, 0.0, -9.81};
  imu::ImuBias bias_hat;  ///< the gyro bias (the accelerometer's is estimated)
  imu::ImuNoise noise;
};

struct LeverArmEstimate {
  /// Add to the configured translation of T_body_lidar (0 in the directions not observable).
  Eigen::Vector3d correction_m = Eigen::Vector3d::Zero();
  /// 1-sigma along body x, y, z: the larger of the formal one (rows independent) and a block
  /// jackknife's (errors correlated over seconds), both kept.
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d formal_sigma_m = Eigen::Vector3d::Zero(),
                  jackknife_sigma_m = Eigen::Vector3d::Zero();
  Eigen::Vector3<bool> observable{false, false, false};
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
  double position_rms_m = 0.0, velocity_rms_mps = 0.0;  ///< residuals of (2)
  std::size_t steps = 0;                                ///< scan-to-scan steps used
};

/// `max_sigma_m`: a direction less certain than this is held. Throws InputError with fewer than
/// 20 steps.
LeverArmEstimate estimateLeverArm(const LeverArmInput& input, double max_sigma_m = 0.01);

}  // namespace taiga::calib
