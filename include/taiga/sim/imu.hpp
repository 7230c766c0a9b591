#pragma once
// Simulated IMU rigidly attached to the body (the body frame is the IMU frame): specific force
// f = R_world_body^T (a_world - g_world) with g_world = (0, 0, -g), and angular rate omega_body,
// both from the exact motion, plus the usual discrete-time noise model (as in Kalibr / GTSAM):
//   f_k = f_true + b_a,k + sigma_a / sqrt(dt) * n,     b_a,k+1 = b_a,k + sigma_ba * sqrt(dt) * n
// (same for the gyro), with a random turn-on bias b_0 ~ N(0, turn_on^2) per axis. Not modelled:
// scale factors, misalignment, g-sensitivity, temperature, an internal orientation filter.

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
  ImuSimulator(ImuParams params, std::uint64_t seed);

  /// Time of the next sample, motion time.
  double nextTime_s() const { return static_cast<double>(k_) / params_.rate_hz; }
  /// The next sample; its time is motion time + time_offset_s.
  ImuSample next(const WalkingMotion& motion, double time_offset_s = 0.0);
  /// Biases applied to the last sample returned (the turn-on biases before the first).
  const ImuBiases& biases() const { return biases_; }

 private:
  ImuParams params_;
  std::uint64_t seed_;
  std::uint64_t k_ = 0;
  ImuBiases biases_;
};

}  // namespace taiga::sim
