#pragma once
// The first state of the odometry from the first IMU readings, without a start ritual.
//
// - At rest (gyroscope and accelerometer readings steady over the window): roll and pitch from the
//   mean specific force (it points up, against gravity), the gyroscope bias from the mean angular
//   rate, velocity zero with a tight prior.
// - Moving from the start: roll and pitch from the mean specific force over the window (a walker's
//   or a machine's accelerations average out over a second far better than they vanish at any
//   instant), zero velocity and gyroscope bias with loose priors. The odometry graph then
//   corrects them within a few seconds: the lidar observes velocity and, through it, tilt.
// - When the IMU reports its own orientation (9-axis IMUs with a filter), roll and pitch come from
//   it, and so does the heading when its reference is east-north-up or north-east-down (turned
//   into ENU), so the map starts north-aligned.
// Otherwise the heading is zero: the world frame's x axis is the body's initial heading.
//
// Accelerometer bias is not separable from tilt at rest and starts at zero with its prior.

#include <cstddef>
#include <span>
#include <string>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/imu/preintegration.hpp"

namespace taiga::imu {

struct InitializationConfig {
  double window_s = 1.0;                ///< readings used, from the first one, s
  double static_gyro_std_radps = 0.02;  ///< at rest when the angular rate's std is below this...
  double static_accel_std_mps2 = 0.15;  ///< ...and the specific force's std below this
  double gravity_mps2 = 9.81;
};

/// 1-sigma of the accelerometer bias a start assumes (a turn-on bias of a MEMS IMU), m/s^2.
inline constexpr double kStartAccelBiasSigma_mps2 = 0.05;

struct InitialState {
  double t_s = 0.0;  ///< time of the last reading used
  NavState state;
  ImuBias bias;
  Eigen::Matrix<double, 15, 15> covariance;  ///< tangent order [dp; dtheta; dv; dba; dbg]
  bool at_rest = false;
  bool from_orientation = false;
  std::string description;  ///< one line for the log, e.g. "at rest: roll 1.2 deg, pitch -0.4 deg"
};

/// The fewest readings initializeFromImu takes.
inline constexpr std::size_t kMinInitializationReadings = 10;

/// Uses the readings within config.window_s of the first one. Throws InputError when there are
/// fewer than kMinInitializationReadings in the window or the specific force is far from gravity (a
/// wrong unit).
InitialState initializeFromImu(std::span<const ImuSample> samples,
                               const InitializationConfig& config = {});

}  // namespace taiga::imu
