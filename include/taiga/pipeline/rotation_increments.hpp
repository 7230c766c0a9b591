#pragma once
// The registrations' rotations between consecutive scans, as the time offset and rotation
// estimator takes them (calib/time_rotation.hpp): shared by `taiga calibrate`'s passes
// (self_calibration.cpp) and the run's clock tracking (clock_tracker.hpp).

#include <cstdint>
#include <optional>

#include "taiga/calib/time_rotation.hpp"
#include "taiga/pipeline/odometry.hpp"

namespace taiga::pipeline {

/// A scan whose registration is a measurement of the body's rotation.
bool measuredByLidar(const ScanOutcome& o);

class RotationIncrements {
 public:
  /// `max_imu_gap_s` (odometry.health.max_imu_gap_s): an increment over which the IMU was silent
  /// for longer has no gyro readings to compare with (the estimators interpolate the rate across
  /// the gap), and is not taken.
  explicit RotationIncrements(double max_imu_gap_s = HealthConfig{}.max_imu_gap_s)
      : max_imu_gap_s_(max_imu_gap_s) {}
  /// The rotation from the previous outcome to `o` (Log(R_prev^T R_o), body frame, at the
  /// outcomes' times) when both were measured, they are consecutive scans, the IMU read through
  /// the interval, and `o` is not the scan at which the odom frame was levelled (its pose changes
  /// frame there).
  std::optional<calib::RotationIncrement> take(const ScanOutcome& o);

 private:
  struct Previous {
    std::uint64_t scan_index = 0;
    double t_s = 0.0;
    bool measured = false;
    lie::SO3 R_odom_body;
  };
  double max_imu_gap_s_;
  std::optional<Previous> previous_;
};

}  // namespace taiga::pipeline
