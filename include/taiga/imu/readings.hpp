#pragma once
// How IMU readings are read between their stamps, in one place for the odometry's propagation
// and preintegration and for the lidar-IMU calibration.
//
// A reading is the rate at its stamp (the simulator's, and that of drivers that sample without
// averaging): between two readings the signal is linear, and a piece's mean is the mean of its
// end values (trapezoid rule). Holding each reading until the next one instead delays the
// integrated motion by half a reading period (2.5 ms at 200 Hz, 5 ms at 100 Hz), which the
// lidar-IMU time offset would then have to absorb. A driver that averages over the period before
// its stamp is half a period late against this convention; the calibrated time offset takes that
// up. Before the first reading and after the last, the nearest one holds.

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <type_traits>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/imu/preintegration.hpp"

namespace taiga::imu {

/// Calls piece(t_from_s, t_to_s, mean) for the pieces of [t0_s, t1_s] split at the readings'
/// stamps, in order, with `mean` the mean of value(reading) over the piece. `samples` (anything
/// indexable with .t_s) must be sorted by time.
template <class Samples, class Value, class Piece>
void forEachPiece(const Samples& samples, double t0_s, double t1_s, Value value, Piece piece) {
  const std::size_t n = samples.size();
  if (n == 0 || !(t1_s > t0_s)) return;
  using V = std::decay_t<decltype(value(samples[0]))>;
  // The first reading after t0_s.
  std::size_t next =
      static_cast<std::size_t>(std::upper_bound(samples.begin(), samples.end(), t0_s,
                                                [](double t, const auto& s) { return t < s.t_s; }) -
                               samples.begin());
  // The signal at t, for t between readings next - 1 and next.
  auto at = [&](double t) -> V {
    if (next == 0) return value(samples[0]);
    if (next == n) return value(samples[n - 1]);
    const auto &a = samples[next - 1], &b = samples[next];
    const double u = (t - a.t_s) / (b.t_s - a.t_s);
    return V((1.0 - u) * value(a) + u * value(b));
  };
  double t = t0_s;
  while (t < t1_s) {
    const double t_next = next < n ? std::min(samples[next].t_s, t1_s) : t1_s;
    if (t_next > t) piece(t, t_next, V(0.5 * (at(t) + at(t_next))));
    t = t_next;
    ++next;
  }
}

/// A reading's acceleration and angular velocity stacked, [a; w]: the value forEachPiece averages
/// for propagation and preintegration.
using AccelGyro = Eigen::Matrix<double, 6, 1>;
inline AccelGyro accelGyro(const ImuSample& s) {
  return (AccelGyro() << s.acceleration_imu_mps2, s.angular_velocity_imu_radps).finished();
}

/// The readings over [t0_s, t1_s] preintegrated ([Forster] Eq. 33), read as above: what the
/// odometry's IMU factor and the lever-arm calibration both need.
template <class Samples>
Preintegrator preintegrateReadings(const Samples& samples, double t0_s, double t1_s,
                                   const ImuBias& bias_hat, const ImuNoise& noise) {
  Preintegrator pre(bias_hat, noise);
  forEachPiece(samples, t0_s, t1_s, accelGyro,
               [&](double piece_from_s, double piece_to_s, const AccelGyro& mean) {
                 pre.integrate(mean.head<3>(), mean.tail<3>(), piece_to_s - piece_from_s);
               });
  return pre;
}

}  // namespace taiga::imu
