#pragma once
// The lidar-IMU time offset followed through a run (issue 20, deliverable 1; docs/calibration.md,
// "During a run"). A lidar that stamps with its own free-running oscillator drifts against the
// IMU's clock by 10-50 ppm: 18 ms after 30 min at 10 ppm, the size of offset error that costs a
// handheld walk decimetres. An offset calibrated on the first 30 s (calibration.at_start) is right
// only there. Every `calibration.track_every_s` of scans, the offset is estimated again from the
// last `track_window_s` of the run's own registrations and gyro readings, with the estimator of
// `taiga calibrate` (calib/time_rotation.hpp, equation (1)), and applied: the latest window's
// value, or, once three windows show a drift beyond 2 sigma, the drift line fitted through them,
// which the offset then follows scan by scan until the next window. A window whose motion does not
// show the offset (held by the estimator's observability test) changes nothing and is counted.
//
// The estimate (about 0.2 s of CPU) runs on its own thread; its result applies from a fixed
// number of scans after the one that started it (waiting for it there if need be), and the scans
// are shifted to it here rather than by the reader, whose read-ahead varies: which scan gets which
// offset does not depend on the threads' timing.

#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include "taiga/calib/time_rotation.hpp"
#include "taiga/core/calibration_config.hpp"
#include "taiga/core/rig_config.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/pipeline/rotation_increments.hpp"
#include "taiga/pipeline/slam_system.hpp"

namespace taiga::pipeline {

/// One re-estimate of the offset.
struct ClockWindow {
  double t_s = 0.0;                  ///< the window's middle (IMU clock)
  double estimate_s = 0.0;           ///< the window's offset (rig.lidar_time_offset_s convention)
  double sigma_s = 0.0;              ///< its 1-sigma (the estimator's)
  bool observable = false;           ///< false: held, estimate_s is the offset in use
  double applied_s = 0.0;            ///< the offset set for the scans read after this window
  double rotation_change_deg = 0.0;  ///< the window's R_body_lidar against the run's (not applied)
  std::size_t increments = 0;
  std::string failed;  ///< why the window gave no estimate; empty when it did
};

/// offset(t) = value_s + slope * (t - t_mean_s), t on the IMU clock.
struct ClockLine {
  double t_mean_s = 0.0, value_s = 0.0;   ///< the windows' weighted mean time and the line there
  double slope = 0.0, slope_sigma = 0.0;  ///< s per s (1e-6: 1 ppm)
};

struct ClockTrackingReport {
  std::vector<ClockWindow> windows;
  double offset_first_s = 0.0;  ///< the offset of the run's first scan
  double offset_last_s = 0.0;   ///< the offset of its last scan
  std::size_t held = 0;         ///< windows that changed nothing (not observable, failed)
  /// The lidar clock's drift against the IMU's fitted through the observable windows, ppm, and
  /// its 1-sigma; empty with fewer than three windows (their middles two re-estimates apart).
  std::optional<double> drift_ppm, drift_sigma_ppm;
  std::string text;  ///< one line for the terminal and summary.json
};

class ClockTracker final : public SlamObserver {
 public:
  /// `set_offset_s` gives the recording the new offset (io::Recording::setLidarTimeOffset).
  ClockTracker(const CalibrationConfig& config, const RigConfig& rig,
               std::function<void(double)> set_offset_s);

  /// Puts the scan on the tracked offset (its times were read with the recording's offset,
  /// io::Scan::lidar_time_offset_s): called for every scan before the SLAM system gets it.
  void adjust(io::Scan& scan);
  void onImu(const ImuSample& sample) override;
  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;

  ClockTrackingReport finish();

 private:
  /// Scans between the one whose outcome starts an estimate and the first that gets its result.
  static constexpr std::uint64_t kApplyAfterScans = 10;

 private:
  struct LidarIncrement {  // a registered rotation on the lidar's own clock
    double t0_lidar_s = 0.0, t1_lidar_s = 0.0;
    Eigen::Vector3d theta_body_rad;
  };
  struct Pending {
    std::uint64_t apply_at_scan = 0;
    std::future<ClockWindow> result;
  };
  double offsetOf(std::uint64_t scan_index) const;
  void start(double t_now_s, std::uint64_t scan_index);
  void apply();
  /// The line through the observable windows of the last kDriftSpan_s before t_s, when its
  /// slope is beyond 2 sigma.
  std::optional<ClockLine> driftLine(double t_s) const;
  void trim(double t_now_s);

  CalibrationConfig config_;
  Eigen::Matrix3d R_body_imu_;
  std::function<void(double)> set_offset_s_;
  double applied_s_;
  std::deque<std::pair<std::uint64_t, double>> scan_offsets_;  // scan index, offset applied
  std::deque<calib::GyroReading> gyro_;
  std::deque<LidarIncrement> increments_;
  RotationIncrements take_;
  std::optional<double> first_scan_s_, last_estimate_s_;
  std::optional<Pending> pending_;
  std::optional<ClockLine> drift_line_;  ///< the offset follows it between windows
  ClockTrackingReport report_;
};

}  // namespace taiga::pipeline
