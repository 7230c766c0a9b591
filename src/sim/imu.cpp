#include "taiga/sim/imu.hpp"

#include <cmath>

#include "taiga/sim/random.hpp"

namespace taiga::sim {
namespace {
Eigen::Vector3d normal3(std::uint64_t seed, std::uint64_t k, std::uint64_t stream) {
  return {hashNormal(seed, k, stream, 0), hashNormal(seed, k, stream, 1),
          hashNormal(seed, k, stream, 2)};
}
}  // namespace

ImuSimulator::ImuSimulator(ImuParams params, std::uint64_t seed)
    : params_(params), seed_(streamSeed(seed, "imu")) {
  if (params_.noise) {
    biases_.accel_mps2 = params_.accel_turn_on_bias * normal3(seed_, 0, 10);
    biases_.gyro_radps = params_.gyro_turn_on_bias * normal3(seed_, 0, 11);
  }
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
  ++k_;
  return sample;
}

}  // namespace taiga::sim
