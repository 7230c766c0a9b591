#include "taiga/imu/initialization.hpp"

#include <fmt/format.h>

#include <cmath>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::imu {
namespace {

struct MeanAndStd {
  Vector3 mean = Vector3::Zero();
  double std = 0.0;  ///< root of the summed per-axis variances
};

template <class Get>
MeanAndStd meanAndStd(std::span<const ImuSample> samples, Get get) {
  MeanAndStd m;
  for (const ImuSample& s : samples) m.mean += get(s);
  m.mean /= static_cast<double>(samples.size());
  for (const ImuSample& s : samples) m.std += (get(s) - m.mean).squaredNorm();
  m.std = std::sqrt(m.std / static_cast<double>(samples.size()));
  return m;
}

/// R_world_body with zero yaw whose z axis is along the specific force at rest:
/// f_body = R^T (0, 0, g) = g (-sin pitch, cos pitch sin roll, cos pitch cos roll).
lie::SO3 tiltFromSpecificForce(const Vector3& f_body) {
  const double roll = std::atan2(f_body.y(), f_body.z());
  const double pitch = std::atan2(-f_body.x(), std::hypot(f_body.y(), f_body.z()));
  return lie::SO3::fromRollPitchYaw(roll, pitch, 0.0);
}

}  // namespace

InitialState initializeFromImu(std::span<const ImuSample> samples,
                               const InitializationConfig& config) {
  std::size_t n = 0;
  while (n < samples.size() && samples[n].t_s - samples.front().t_s <= config.window_s) ++n;
  if (n < kMinInitializationReadings) {
    throw InputError(
        fmt::format("IMU initialization needs at least {} readings in its first {:.2f} s, got {}",
                    kMinInitializationReadings, config.window_s, n));
  }
  const std::span<const ImuSample> window = samples.first(n);
  const MeanAndStd gyro =
      meanAndStd(window, [](const ImuSample& s) { return s.angular_velocity_imu_radps; });
  const MeanAndStd accel =
      meanAndStd(window, [](const ImuSample& s) { return s.acceleration_imu_mps2; });
  const double f_norm = accel.mean.norm();
  if (std::abs(f_norm - config.gravity_mps2) > 0.3 * config.gravity_mps2) {
    throw InputError(fmt::format(
        "IMU initialization: the mean specific force over the first {:.2f} s is {:.3f} m/s^2, "
        "far from gravity ({:.2f}): the accelerometer unit is probably wrong "
        "(rig.imu_acceleration_unit)",
        config.window_s, f_norm, config.gravity_mps2));
  }

  InitialState init;
  init.t_s = window.back().t_s;
  init.at_rest =
      gyro.std < config.static_gyro_std_radps && accel.std < config.static_accel_std_mps2;
  const lie::SO3 R_tilt_body = tiltFromSpecificForce(accel.mean);
  init.state.R_world_body = R_tilt_body;
  const ImuSample& last = window.back();
  if (last.orientation && last.orientation->reference != OrientationReference::kUnknown) {
    const lie::SO3 R_reference_imu(last.orientation->q_reference_imu);
    // NED to ENU: x_enu = y_ned, y_enu = x_ned, z_enu = -z_ned.
    Matrix3 R_enu_ned;
    R_enu_ned << 0, 1, 0, 1, 0, 0, 0, 0, -1;
    init.state.R_world_body = last.orientation->reference == OrientationReference::kEnu
                                  ? R_reference_imu
                                  : lie::SO3::fromMatrix(R_enu_ned * R_reference_imu.matrix());
    init.from_orientation = true;
  } else if (last.orientation) {
    // Gravity-aligned with an arbitrary heading: keep its roll and pitch, zero the yaw.
    const Matrix3 R = lie::SO3(last.orientation->q_reference_imu).matrix();
    init.state.R_world_body =
        lie::SO3::fromRollPitchYaw(std::atan2(R(2, 1), R(2, 2)), -std::asin(R(2, 0)), 0.0);
    init.from_orientation = true;
  }
  // At rest the mean specific force measures the tilt directly (to the accelerometer bias over
  // g: 0.3 deg at 0.05 m/s^2); an orientation filter's tilt rests on the same accelerometer plus
  // its own dynamics and is often a degree off (simulated 9-axis IMUs: 0.7-1.4 deg). So at rest
  // the orientation output gives the heading only.
  if (init.at_rest && init.from_orientation)
    init.state.R_world_body = lie::SO3::fromRollPitchYaw(0.0, 0.0, init.state.R_world_body.yaw()) *
                              R_tilt_body;
  if (init.at_rest) init.bias.gyro_radps = gyro.mean;

  // Priors: position and heading fix the gauge of the world frame; tilt, velocity and biases are
  // as uncertain as the way they were found.
  const double tilt_sigma =
      init.at_rest || init.from_orientation ? 0.5 / kDegPerRad : 3.0 / kDegPerRad;
  const double velocity_sigma = init.at_rest ? 0.01 : 1.0;
  const double gyro_bias_sigma =
      init.at_rest ? gyro.std / std::sqrt(static_cast<double>(n)) + 1e-4 : 0.02;
  init.covariance.setZero();
  init.covariance.diagonal() << Vector3::Constant(1e-6), tilt_sigma * tilt_sigma,
      tilt_sigma * tilt_sigma, 1e-6, Vector3::Constant(velocity_sigma * velocity_sigma),
      Vector3::Constant(kStartAccelBiasSigma_mps2 * kStartAccelBiasSigma_mps2),
      Vector3::Constant(gyro_bias_sigma * gyro_bias_sigma);

  const Matrix3 R = init.state.R_world_body.matrix();
  const Vector3 rpy_deg =
      Vector3(std::atan2(R(2, 1), R(2, 2)), -std::asin(R(2, 0)), init.state.R_world_body.yaw()) *
      kDegPerRad;
  init.description = fmt::format(
      "{}{}: roll {:.2f} deg, pitch {:.2f} deg, yaw {:.2f} deg from {} readings over {:.2f} s",
      init.at_rest ? "at rest" : "moving", init.from_orientation ? " (IMU orientation)" : "",
      rpy_deg.x(), rpy_deg.y(), rpy_deg.z(), n, init.t_s - window.front().t_s);
  return init;
}

}  // namespace taiga::imu
