#pragma once
// The IMU's continuous-time noise model (white noise densities and bias random walks, as in a
// datasheet or an Allan deviation plot). One struct for the configuration (ImuNoiseConfig
// extends it) and for the preintegration that propagates it (imu::Preintegrator).

namespace taiga {

struct ImuNoise {
  double accel_noise_density = 2.0e-3;     ///< m/s^2/sqrt(Hz)
  double gyro_noise_density = 1.7e-4;      ///< rad/s/sqrt(Hz)
  double accel_bias_random_walk = 3.0e-4;  ///< m/s^3/sqrt(Hz)
  double gyro_bias_random_walk = 2.0e-5;   ///< rad/s^2/sqrt(Hz)
};

}  // namespace taiga
