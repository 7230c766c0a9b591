#pragma once
// Simulated IMU rigidly attached to the body (the body frame is the IMU frame): specific force
// f = R_world_body^T (a_world - g_world) with g_world = (0, 0, -g), and angular rate omega_body,
// both from the exact motion, plus the usual discrete-time noise model (as in Kalibr / GTSAM):
//   f_k = f_true + b_a,k + sigma_a / sqrt(dt) * n,     b_a,k+1 = b_a,k + sigma_ba * sqrt(dt) * n
// (same for the gyro), with a random turn-on bias b_0 ~ N(0, turn_on^2) per axis.
//
// Optional orientation output (params.orientation_output), as an IMU module's internal attitude
// filter without a magnetometer reports it: the true R_enu_body perturbed on the left,
//   R_reported = Rz(psi_k) Exp([e_x,k, e_y,k, 0]) R_enu_body,
// with a tilt error e (first-order Gauss-Markov per axis, sigma_tilt, time constant tau:
// e_k+1 = phi e_k + sqrt(1 - phi^2) sigma_tilt n, phi = exp(-dt / tau)) and a heading error
// psi_k = offset + random walk (psi_k+1 = psi_k + q sqrt(dt) n). With noise = false the reported
// orientation is exact. Not modelled: temperature, the filter's response to accelerations (its
// tilt error does not grow in turns).
//
// Realism (docs/simulator.md, "Realism"; all off in the ideal preset): the true noise densities
// and bias walks are the stated ones times noise_density_factor and bias_walk_factor; the
// measured vectors are M f_true (M = I + scale errors + axis misalignments, drawn per seed) with
// a gyro g-sensitivity G f_true, a first-order Gauss-Markov bias on top of the random walk, and
// clipping at the sensor's range; each stamp carries jitter.

#include <Eigen/Core>
#include <cstdint>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/sim/motion.hpp"
#include "taiga/sim/scenario.hpp"

namespace taiga::sim {

struct ImuBiases {
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
};

/// Produces samples k = 0, 1, 2, ... at t_k = k / rate_hz (motion time) in order.
class ImuSimulator {
 public:
  /// world_yaw_deg: heading of the world frame (angle from east to world x, counterclockwise),
  /// for the orientation output, which refers to east-north-up (REP-103).
  ImuSimulator(ImuParams params, std::uint64_t seed, double world_yaw_deg = 0.0);

  /// Time of the next sample, motion time.
  double nextTime_s() const { return static_cast<double>(k_) / params_.rate_hz; }
  /// The next sample; its time is motion time + time_offset_s.
  ImuSample next(const WalkingMotion& motion, double time_offset_s = 0.0);
  /// Turn-on and random-walk biases applied to the last sample returned (the turn-on biases
  /// before the first); the Gauss-Markov part is markovBiases().
  const ImuBiases& biases() const { return biases_; }
  const ImuBiases& markovBiases() const { return markov_; }
  /// The gyro's scale and axis errors, drawn from the seed: reading = this * true rate (+ bias,
  /// g-sensitivity, noise). rig_truth.yaml's rig.gyro_axes.
  const Eigen::Matrix3d& gyroAxes() const { return M_gyro_; }
  /// Errors of the orientation given with the last sample: tilt about east and north, heading
  /// about up, rad (zero when the output is off or noise is false).
  Eigen::Vector3d orientationError_rad() const {
    return {tilt_error_rad_.x(), tilt_error_rad_.y(), heading_error_rad_};
  }

 private:
  void advanceOrientationError();
  void advanceMarkovBiases(double dt);
  bool hasMarkovBiases() const {
    return params_.accel_bias_instability_mps2 > 0.0 || params_.gyro_bias_instability_radps > 0.0;
  }

  ImuParams params_;
  std::uint64_t seed_;
  std::uint64_t k_ = 0;
  ImuBiases biases_;
  ImuBiases markov_;
  bool has_axis_errors_ = false;
  Eigen::Matrix3d M_accel_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d M_gyro_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d G_gyro_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d R_enu_world_ = Eigen::Matrix3d::Identity();
  Eigen::Vector2d tilt_error_rad_ = Eigen::Vector2d::Zero();
  double heading_error_rad_ = 0.0;
};

}  // namespace taiga::sim
