#include "taiga/imu/propagation.hpp"

#include <algorithm>
#include <stdexcept>

#include "taiga/imu/readings.hpp"

namespace taiga::imu {

NavState propagate(const NavState& state, const Vector3& accel_body_mps2,
                   const Vector3& gyro_body_radps, double dt_s, const Vector3& gravity_world) {
  const Vector3 accel_world = state.R_world_body * accel_body_mps2 + gravity_world;
  NavState next;
  next.p_world = state.p_world + state.v_world * dt_s + 0.5 * accel_world * dt_s * dt_s;
  next.v_world = state.v_world + accel_world * dt_s;
  next.R_world_body = state.R_world_body * lie::SO3::Exp(gyro_body_radps * dt_s);
  return next;
}

std::vector<StampedNavState> propagateThrough(const NavState& start, double t_start_s,
                                              double t_end_s, std::span<const ImuSample> samples,
                                              const ImuBias& bias, const Vector3& gravity_world) {
  if (samples.empty()) throw std::invalid_argument("propagateThrough: no IMU samples");
  if (t_end_s < t_start_s)
    throw std::invalid_argument("propagateThrough: t_end_s before t_start_s");
  std::vector<StampedNavState> states{{t_start_s, start}};
  forEachPiece(
      samples, t_start_s, t_end_s, accelGyro,
      [&](double t_from_s, double t_to_s, const AccelGyro& mean) {
        states.push_back({t_to_s, propagate(states.back().state, mean.head<3>() - bias.accel_mps2,
                                            mean.tail<3>() - bias.gyro_radps, t_to_s - t_from_s,
                                            gravity_world)});
      });
  return states;
}

Trajectory toTrajectory(const std::vector<StampedNavState>& states) {
  Trajectory trajectory;
  for (const StampedNavState& s : states) {
    trajectory.append(s.t_s, lie::SE3(s.state.R_world_body, s.state.p_world));
  }
  return trajectory;
}

}  // namespace taiga::imu
