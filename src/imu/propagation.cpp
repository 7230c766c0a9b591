#include "taiga/imu/propagation.hpp"

#include <algorithm>
#include <stdexcept>

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
  // The reading in force at t_start_s: the latest sample at or before it, else the first one.
  auto in_force = std::upper_bound(samples.begin(), samples.end(), t_start_s,
                                   [](double t, const ImuSample& s) { return t < s.t_s; });
  if (in_force != samples.begin()) --in_force;

  std::vector<StampedNavState> states{{t_start_s, start}};
  double t = t_start_s;
  NavState state = start;
  while (t < t_end_s) {
    auto next = std::next(in_force);
    const double t_next =
        (next != samples.end() && next->t_s < t_end_s) ? std::max(next->t_s, t) : t_end_s;
    if (t_next > t) {
      state = propagate(state, in_force->acceleration_imu_mps2 - bias.accel_mps2,
                        in_force->angular_velocity_imu_radps - bias.gyro_radps, t_next - t,
                        gravity_world);
      t = t_next;
      states.push_back({t, state});
    }
    if (next == samples.end() || next->t_s >= t_end_s) break;
    in_force = next;
  }
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
