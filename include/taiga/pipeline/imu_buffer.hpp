#pragma once
// IMU readings kept between scans: what preintegration, deskewing and IMU-rate poses read.
//
// Between readings the signal is linear (imu/readings.hpp), the same model as
// imu::propagateThrough, so preintegrated factors and propagated poses agree.

#include <deque>
#include <span>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/imu/preintegration.hpp"

namespace taiga::pipeline {

class ImuBuffer {
 public:
  /// Appends a reading; readings not after the last one are ignored (returns false).
  bool add(const ImuSample& sample);
  bool empty() const { return samples_.empty(); }
  double firstTime() const { return samples_.front().t_s; }
  double lastTime() const { return samples_.back().t_s; }
  /// The longest time within [t_from_s, t_to_s] without a reading (the stretch after the last
  /// reading up to t_to_s included): a gap in the IMU stream, s.
  double longestGap(double t_from_s, double t_to_s) const;
  /// The readings from the one in force at t_from_s (the latest at or before it) up to t_to_s.
  std::vector<ImuSample> between(double t_from_s, double t_to_s) const;
  /// The same and the first reading after t_to_s, when there is one: all that the signal over
  /// the interval depends on (what propagation reads).
  std::vector<ImuSample> signalOver(double t_from_s, double t_to_s) const;
  /// All readings, oldest first (for initialization).
  std::vector<ImuSample> all() const { return {samples_.begin(), samples_.end()}; }
  /// Preintegrates the readings over [t_from_s, t_to_s].
  imu::Preintegrator preintegrate(double t_from_s, double t_to_s, const imu::ImuBias& bias_hat,
                                  const imu::ImuNoise& noise) const;
  /// Forgets readings that no interval starting at or after t_s needs.
  void dropBefore(double t_s);

 private:
  std::deque<ImuSample> samples_;
};

}  // namespace taiga::pipeline
