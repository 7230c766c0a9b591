#include "taiga/sim/imu.hpp"

#include <Eigen/Geometry>
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
}  // namespace

ImuSimulator::ImuSimulator(ImuParams params, std::uint64_t seed, double world_yaw_deg)
    : params_(params), seed_(streamSeed(seed, "imu")) {
  if (params_.noise) {
    biases_.accel_mps2 = params_.accel_turn_on_bias * normal3(seed_, 0, 10);
    biases_.gyro_radps = params_.gyro_turn_on_bias * normal3(seed_, 0, 11);
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

ImuSample ImuSimulator::next(const WalkingMotion& motion, double time_offset_s) {
  const double t = nextTime_s();
  const MotionState state = motion.at(t);
  const Eigen::Vector3d g_world(0.0, 0.0, -params_.gravity_mps2);
  ImuSample sample;
  sample.t_s = t + time_offset_s;
  sample.acceleration_imu_mps2 =
      state.T_world_body.rotation().inverse() * (state.a_world - g_world);
  sample.angular_velocity_imu_radps = state.omega_body;
  if (params_.noise) {
    const double dt = 1.0 / params_.rate_hz;
    if (k_ > 0) {  // bias random walk from the previous sample to this one
      biases_.accel_mps2 += params_.accel_bias_random_walk * std::sqrt(dt) * normal3(seed_, k_, 2);
      biases_.gyro_radps += params_.gyro_bias_random_walk * std::sqrt(dt) * normal3(seed_, k_, 3);
    }
    sample.acceleration_imu_mps2 +=
        biases_.accel_mps2 + params_.accel_noise_density / std::sqrt(dt) * normal3(seed_, k_, 0);
    sample.angular_velocity_imu_radps +=
        biases_.gyro_radps + params_.gyro_noise_density / std::sqrt(dt) * normal3(seed_, k_, 1);
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
