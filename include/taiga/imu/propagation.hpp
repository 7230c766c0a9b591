#pragma once
// Dead reckoning with the IMU: a navigation state carried forward through IMU samples, for the
// poses inside a scan (deskewing, thesis Eq. 34-35) and IMU-rate poses between scans.
//
// Integration is the same first-order scheme as the preintegration ([Forster] Eq. 33 in the world
// frame), over the pieces between readings with each piece's mean reading (imu/readings.hpp).

#include <span>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/imu/preintegration.hpp"

namespace taiga::imu {

struct StampedNavState {
  double t_s = 0.0;
  NavState state;
};

/// One step of length dt_s with the bias-corrected readings held constant.
NavState propagate(const NavState& state, const Vector3& accel_body_mps2,
                   const Vector3& gyro_body_radps, double dt_s, const Vector3& gravity_world);

/// The states at t_start_s, at every sample time inside (t_start_s, t_end_s), and at t_end_s,
/// starting from `start` at t_start_s. `samples` must be sorted by time and should begin at or
/// before t_start_s; between them the readings are linear (imu/readings.hpp). Readings are
/// corrected by `bias`. Throws
/// std::invalid_argument when `samples` is empty or t_end_s < t_start_s.
std::vector<StampedNavState> propagateThrough(const NavState& start, double t_start_s,
                                              double t_end_s, std::span<const ImuSample> samples,
                                              const ImuBias& bias, const Vector3& gravity_world);

/// The body poses T_world_body of propagated states, as a trajectory to interpolate.
Trajectory toTrajectory(const std::vector<StampedNavState>& states);

}  // namespace taiga::imu
