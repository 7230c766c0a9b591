#include "taiga/sim/imu.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "taiga/core/angles.hpp"
#include "taiga/lie/so3.hpp"
#include "taiga/sim/random.hpp"

namespace taiga::sim {
namespace {

Eigen::Vector3d normal3(std::uint64_t seed, std::uint64_t k, std::uint64_t stream) {
  return {hashNormal(seed, k, stream, 0), hashNormal(seed, k, stream, 1),
          hashNormal(seed, k, stream, 2)};
}

Eigen::Matrix3d normal33(std::uint64_t seed, std::uint64_t stream) {
  Eigen::Matrix3d m;
  for (int c = 0; c < 3; ++c) m.col(c) = normal3(seed, static_cast<std::uint64_t>(c), stream);
  return m;
}

/// I + diag(scale errors) + off-diagonal axis misalignments: the sensor's axes as built.
Eigen::Matrix3d axisErrors(const ImuParams& p, std::uint64_t seed, std::uint64_t stream) {
  const Eigen::Matrix3d n = normal33(seed, stream);
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      m(r, c) += (r == c ? p.scale_factor_error : p.misalignment_deg * kRadPerDeg) * n(r, c);
  return m;
}

Eigen::Vector3d clip(const Eigen::Vector3d& v, double range) {
  return range > 0.0 ? v.cwiseMax(-range).cwiseMin(range) : v;
}
}  // namespace

ImuSimulator::ImuSimulator(ImuParams params, std::uint64_t seed, double world_yaw_deg)
    : params_(params), seed_(streamSeed(seed, "imu")) {
  if (params_.noise) {
    biases_.accel_mps2 = params_.accel_turn_on_bias * normal3(seed_, 0, 10);
    biases_.gyro_radps = params_.gyro_turn_on_bias * normal3(seed_, 0, 11);
    // Streams 30-37: the realism errors leave the draws of an ideal IMU unchanged.
    has_axis_errors_ = params_.scale_factor_error > 0.0 || params_.misalignment_deg > 0.0;
    if (has_axis_errors_) {
      M_accel_ = axisErrors(params_, seed_, 30);
      M_gyro_ = axisErrors(params_, seed_, 31);
    }
    // g-sensitivity: gyro error = G f (rad/s per m/s^2 of specific force).
    G_gyro_ = params_.gyro_g_sensitivity_deg_s_per_g * kRadPerDeg / params_.gravity_mps2 *
              normal33(seed_, 32);
    // Gauss-Markov biases start in their stationary distribution.
    markov_.accel_mps2 = params_.accel_bias_instability_mps2 * normal3(seed_, 0, 33);
    markov_.gyro_radps = params_.gyro_bias_instability_radps * normal3(seed_, 0, 34);
  }
  R_enu_world_ =
      Eigen::AngleAxisd(world_yaw_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  if (params_.orientation_output && params_.noise) {
    // Streams 20-22: the orientation's draws leave the accelerometer and gyro noise unchanged.
    const Eigen::Vector3d n = normal3(seed_, 0, 20);
    tilt_error_rad_ = params_.orientation_tilt_error_deg * kRadPerDeg * n.head<2>();
    heading_error_rad_ = params_.orientation_heading_offset_deg * kRadPerDeg;
  }
}

void ImuSimulator::advanceOrientationError() {
  const double dt = 1.0 / params_.rate_hz;
  const double phi = std::exp(-dt / params_.orientation_tilt_correlation_s);
  const Eigen::Vector3d n = normal3(seed_, k_, 21);
  tilt_error_rad_ = phi * tilt_error_rad_ + std::sqrt(1.0 - phi * phi) *
                                                params_.orientation_tilt_error_deg * kRadPerDeg *
                                                n.head<2>();
  heading_error_rad_ +=
      params_.orientation_heading_walk_deg_per_sqrt_s * kRadPerDeg * std::sqrt(dt) * n.z();
}

void ImuSimulator::advanceMarkovBiases(double dt) {
  // First-order Gauss-Markov: b_k+1 = phi b_k + sqrt(1 - phi^2) sigma n, phi = exp(-dt / tau).
  const double phi = std::exp(-dt / params_.bias_correlation_s);
  const double q = std::sqrt(1.0 - phi * phi);
  markov_.accel_mps2 = phi * markov_.accel_mps2 +
                       q * params_.accel_bias_instability_mps2 * normal3(seed_, k_, 35);
  markov_.gyro_radps = phi * markov_.gyro_radps +
                       q * params_.gyro_bias_instability_radps * normal3(seed_, k_, 36);
}

ImuSample ImuSimulator::next(const WalkingMotion& motion, double time_offset_s) {
  const double t = nextTime_s();
  const MotionState state = motion.at(t);
  const Eigen::Vector3d g_world(0.0, 0.0, -params_.gravity_mps2);
  ImuSample sample;
  sample.t_s = t + time_offset_s;
  const Eigen::Vector3d f_true =
      state.T_world_body.rotation().inverse() * (state.a_world - g_world);
  sample.acceleration_imu_mps2 = f_true;
  sample.angular_velocity_imu_radps = state.omega_body;
  if (params_.noise) {
    const double dt = 1.0 / params_.rate_hz;
    if (has_axis_errors_) {
      sample.acceleration_imu_mps2 = M_accel_ * f_true;
      sample.angular_velocity_imu_radps = M_gyro_ * state.omega_body;
    }
    if (params_.gyro_g_sensitivity_deg_s_per_g > 0.0)
      sample.angular_velocity_imu_radps += G_gyro_ * f_true;
    if (k_ > 0) {  // bias random walk from the previous sample to this one
      biases_.accel_mps2 += params_.accel_bias_random_walk * params_.bias_walk_factor *
                            std::sqrt(dt) * normal3(seed_, k_, 2);
      biases_.gyro_radps += params_.gyro_bias_random_walk * params_.bias_walk_factor *
                            std::sqrt(dt) * normal3(seed_, k_, 3);
      if (hasMarkovBiases()) advanceMarkovBiases(dt);
    }
    sample.acceleration_imu_mps2 +=
        biases_.accel_mps2 + params_.accel_noise_density * params_.noise_density_factor /
                                 std::sqrt(dt) * normal3(seed_, k_, 0);
    sample.angular_velocity_imu_radps +=
        biases_.gyro_radps + params_.gyro_noise_density * params_.noise_density_factor /
                                 std::sqrt(dt) * normal3(seed_, k_, 1);
    if (hasMarkovBiases()) {
      sample.acceleration_imu_mps2 += markov_.accel_mps2;
      sample.angular_velocity_imu_radps += markov_.gyro_radps;
    }
    sample.acceleration_imu_mps2 =
        clip(sample.acceleration_imu_mps2, params_.accel_range_g * params_.gravity_mps2);
    sample.angular_velocity_imu_radps =
        clip(sample.angular_velocity_imu_radps, params_.gyro_range_deg_s * kRadPerDeg);
    if (params_.timestamp_jitter_s > 0.0) {  // stamps stay in order: within +-0.45 periods
      const double jitter_s = params_.timestamp_jitter_s * hashNormal(seed_, k_, 37);
      sample.t_s += std::clamp(jitter_s, -0.45 * dt, 0.45 * dt);
    }
  }
  if (params_.orientation_output) {
    if (params_.noise && k_ > 0) advanceOrientationError();
    const Eigen::Matrix3d R_enu_body = R_enu_world_ * state.T_world_body.rotation().matrix();
    const Eigen::Matrix3d R_error =
        Eigen::AngleAxisd(heading_error_rad_, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        lie::SO3::Exp(Eigen::Vector3d(tilt_error_rad_.x(), tilt_error_rad_.y(), 0.0)).matrix();
    sample.orientation = ImuOrientation{Eigen::Quaterniond(R_error * R_enu_body).normalized(),
                                        OrientationReference::kEnu};
  }
  ++k_;
  return sample;
}

}  // namespace taiga::sim
