#include "health_monitor.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/core/percentile.hpp"

namespace taiga::pipeline {
namespace {

/// Ok scans needed before the history is a yardstick.
constexpr std::size_t kMinHistory = 5;

void append(std::string& reasons, const std::string& reason) {
  if (reason.empty()) return;
  if (!reasons.empty()) reasons += "; ";
  reasons += reason;
}

double medianOf(const std::deque<double>& history) {
  return percentile(std::vector<double>(history.begin(), history.end()), 50.0);
}

void pushCapped(std::deque<double>& history, double value, int capacity) {
  history.push_back(value);
  while (history.size() > static_cast<std::size_t>(capacity)) history.pop_front();
}

}  // namespace

std::string HealthMonitor::historyProblems(const HealthEvidence& scan) const {
  if (!scan.registered || scan.lidar != LidarFactor::kUsed) return {};
  std::string reasons;
  if (fitness_history_m2_.size() >= kMinHistory) {
    const double median_fitness_m2 = medianOf(fitness_history_m2_);
    if (scan.fitness_m2 > config_.fitness_floor_m2 &&
        scan.fitness_m2 > config_.fitness_ratio * median_fitness_m2)
      append(reasons,
             fmt::format("fitness {:.3f} m^2 is {:.1f}x the recent median {:.3f}", scan.fitness_m2,
                         scan.fitness_m2 / median_fitness_m2, median_fitness_m2));
  }
  if (inlier_share_history_.size() < kMinHistory) return reasons;
  const double median_share = medianOf(inlier_share_history_);
  if (scan.inlier_share < config_.inlier_share_ratio * median_share)
    append(reasons, fmt::format("{:.0f} % of the points matched the map, recently {:.0f} %",
                                100.0 * scan.inlier_share, 100.0 * median_share));
  return reasons;
}

std::string HealthMonitor::limitProblems(const HealthEvidence& scan, bool& impossible) const {
  std::string reasons;
  const double speed_mps = scan.v_odom.norm();
  impossible = !scan.v_odom.allFinite() || speed_mps > config_.max_speed_mps;
  if (impossible)
    append(reasons, fmt::format("speed {:.1f} m/s is beyond the rig's {:.0f}", speed_mps,
                                config_.max_speed_mps));
  if (previous_t_s_ && scan.t_s > *previous_t_s_) {
    const double acceleration_mps2 =
        (scan.v_odom - previous_v_odom_).norm() / (scan.t_s - *previous_t_s_);
    if (acceleration_mps2 > config_.max_acceleration_mps2)
      append(reasons, fmt::format("velocity jumped at {:.0f} m/s^2", acceleration_mps2));
  }
  if (scan.estimates_bias) {
    const double accel_bias_mps2 = scan.bias.accel_mps2.norm();
    const double gyro_bias_dps = scan.bias.gyro_radps.norm() * kDegPerRad;
    if (scan.frame_levelled && accel_bias_mps2 > config_.max_accel_bias_mps2)
      append(reasons, fmt::format("accelerometer bias estimate {:.2f} m/s^2 is implausible",
                                  accel_bias_mps2));
    if (gyro_bias_dps > config_.max_gyro_bias_dps)
      append(reasons,
             fmt::format("gyroscope bias estimate {:.1f} deg/s is implausible", gyro_bias_dps));
  }
  if (scan.imu_gap_s > config_.max_imu_gap_s)
    append(reasons, fmt::format("no IMU readings for {:.2f} s", scan.imu_gap_s));
  if (scan.registered && scan.lidar == LidarFactor::kRejected)
    append(reasons, "lidar factor rejected: " + scan.lidar_note);
  if (scan.registered && scan.lidar == LidarFactor::kInflated) append(reasons, scan.lidar_note);
  return reasons;
}

void HealthMonitor::remember(const HealthEvidence& scan) {
  // Only ok scans, and never while lost: a yardstick that learned from scans it distrusted would
  // soon call a broken registration normal (measured: a lidar-only run at 2 Hz went on for 30 m
  // with 8 % of its points on the map, "ok"). A lasting change of scene that the checks distrust
  // therefore loses the track, and the local map and its yardstick start over.
  if (!scan.registered || scan.lidar != LidarFactor::kUsed || lost_since_t_s_) return;
  pushCapped(inlier_share_history_, scan.inlier_share, config_.history_scans);
  // A rig standing on its first keyframe learned the fitness of identical views (0.039 m^2,
  // harvester, 32 beams); driving off, a ring-sparse map fitted 4x that 0.3 m on, every scan was
  // degraded and the track was lost (BENCHMARK.md, session 41). The inlier share stays: moving
  // on, a scan that matches half as much as it did standing was 0.2 m off (16 beams).
  if (!scan.at_keyframe_viewpoint)
    pushCapped(fitness_history_m2_, scan.fitness_m2, config_.history_scans);
}

ScanHealth HealthMonitor::judge(const HealthEvidence& scan) {
  if (!last_ok_t_s_) last_ok_t_s_ = scan.t_s;  // the first scan starts the clock
  bool impossible = false;
  ScanHealth health;
  append(health.reason, limitProblems(scan, impossible));
  append(health.reason, historyProblems(scan));
  const bool good = health.reason.empty();
  previous_t_s_ = scan.t_s;
  previous_v_odom_ = scan.v_odom;
  restart_local_map_ = false;
  if (good) remember(scan);

  // Lost takes both time and scans (1 s is 10 scans at 10 Hz but 2 at 2 Hz).
  not_ok_in_a_row_ = good ? 0 : not_ok_in_a_row_ + 1;
  if (good) last_ok_t_s_ = scan.t_s;
  const double not_ok_s = scan.t_s - *last_ok_t_s_;
  const bool long_not_ok =
      not_ok_s > config_.lost_after_s && not_ok_in_a_row_ >= config_.lost_after_scans;
  // Recovery takes scans that pass every check, against the yardstick from before the loss.
  ok_in_a_row_ = good ? ok_in_a_row_ + 1 : 0;
  if (good && lost_since_t_s_ && ok_in_a_row_ < config_.recovery_scans) {
    health.status = ScanStatus::kLost;
    health.reason =
        fmt::format("recovering: {} of {} scans ok", ok_in_a_row_, config_.recovery_scans);
  } else if (good) {
    if (lost_since_t_s_)
      health.reason = fmt::format("recovered, lost since {:.3f} s", *lost_since_t_s_);
    lost_since_t_s_.reset();
    health.status = ScanStatus::kOk;
  } else if (impossible || lost_since_t_s_ || long_not_ok) {
    if (!lost_since_t_s_) lost_since_t_s_ = lost_on_this_map_since_t_s_ = scan.t_s;
    health.status = ScanStatus::kLost;
    if (!impossible)
      health.reason = fmt::format("no scan ok for {:.1f} s: {}", not_ok_s, health.reason);
    restart_local_map_ = scan.t_s - *lost_on_this_map_since_t_s_ > config_.reinitialize_after_s;
  } else {
    health.status = ScanStatus::kDegraded;
  }
  return health;
}

bool HealthMonitor::hasYardstick() const { return inlier_share_history_.size() >= kMinHistory; }

bool HealthMonitor::registrationSuspect(double fitness_m2, double inlier_share) const {
  if (!std::isfinite(fitness_m2) || fitness_m2 > max_fitness_m2_) return true;
  return !historyProblems({.registered = true,
                           .lidar = LidarFactor::kUsed,
                           .fitness_m2 = fitness_m2,
                           .inlier_share = inlier_share})
              .empty();
}

void HealthMonitor::forgetHistory() {
  fitness_history_m2_.clear();
  inlier_share_history_.clear();
}

void HealthMonitor::localMapRestarted(double t_s) {
  forgetHistory();
  lost_on_this_map_since_t_s_ = t_s;
  restart_local_map_ = false;
  // The clock restarts too: the new map's first scans are judged on their own.
  last_ok_t_s_.reset();
  not_ok_in_a_row_ = 0;
}

}  // namespace taiga::pipeline
