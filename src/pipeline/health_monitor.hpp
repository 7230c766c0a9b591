#pragma once
// The odometry's health monitor (docs/odometry.md, "Health"): every scan gets a status, ok,
// degraded or lost, with the reason, judged against the run's own recent history rather than
// against absolute limits alone, so that a forest, a field and a corridor each set their own
// yardstick. Only ok scans become keyframes (odometry.cpp), so a scan the monitor distrusts never
// enters the local map. Internal to the pipeline.

#include <deque>
#include <optional>
#include <string>

#include "taiga/core/odometry_config.hpp"
#include "taiga/pipeline/odometry.hpp"

namespace taiga::pipeline {

/// A registration's inliers over the scan's source points, 0..1 (HealthEvidence::inlier_share).
inline double inlierShare(const registration::RegistrationResult& r, std::size_t source_points) {
  return source_points > 0 ? static_cast<double>(r.num_inliers) / static_cast<double>(source_points)
                           : 0.0;
}

/// What the monitor is shown of one scan.
struct HealthEvidence {
  double t_s = 0.0;
  /// False for the scans before the local map has its first keyframe: nothing to judge.
  bool registered = false;
  LidarFactor lidar = LidarFactor::kFirstScan;
  std::string lidar_note;
  double fitness_m2 = 0.0;
  /// Inliers of the registration over the scan's source points, 0..1.
  double inlier_share = 0.0;
  /// The state after fusion and whether its biases are estimated (an IMU).
  Eigen::Vector3d v_odom = Eigen::Vector3d::Zero();
  imu::ImuBias bias;
  bool estimates_bias = false;
  /// Until the IMU's gravity alignment levels the odom frame, the accelerometer bias absorbs the
  /// start frame's tilt error by design (3.8 m/s^2 for a walk that starts in a U-turn: 22 deg),
  /// so it is judged only after.
  bool frame_levelled = true;
  double imu_gap_s = 0.0;  ///< the longest stretch without IMU readings before the scan, s
  /// Registered from near the last keyframe's own viewpoint (standing, or just after a
  /// keyframe): it matches mostly the points it was made of, so its fitness says nothing of what
  /// the scans a metre on will show and never enters the fitness yardstick.
  bool at_keyframe_viewpoint = false;
};

class HealthMonitor {
 public:
  /// `max_fitness_m2`: the odometry's limit above which a registration is rejected.
  HealthMonitor(const HealthConfig& config, double max_fitness_m2)
      : config_(config), max_fitness_m2_(max_fitness_m2) {}

  ScanHealth judge(const HealthEvidence& scan);
  /// Whether a registration would be judged a problem, before it is fused: a fitness that is
  /// not finite or above max_fitness_m2, or far from the recent history.
  bool registrationSuspect(double fitness_m2, double inlier_share) const;
  /// Whether the recent history is long enough to judge against (not right after the local map
  /// started over); the fitness may still lack one (a rig standing since the start).
  bool hasYardstick() const;
  /// Time from the last ok scan to t_s, s; 0 before the first scan.
  double sinceOk_s(double t_s) const { return last_ok_t_s_ ? t_s - *last_ok_t_s_ : 0.0; }
  /// True when the scan just judged asks for a fresh local map: lost on the current one for
  /// longer than reinitialize_after_s.
  bool restartLocalMap() const { return restart_local_map_; }
  /// The local map was restarted after a loss: the next scans rebuild the history and start the
  /// clock anew.
  void localMapRestarted(double t_s);
  /// The local map starts over for another reason (the odom frame levelled): its first scans
  /// match less of it than the old map's did, so the history starts over.
  void forgetHistory();

 private:
  /// Problems against fixed limits: a rejected or inflated lidar factor, a velocity jump,
  /// implausible biases; `impossible` for a state no rig can have (lost at once).
  std::string limitProblems(const HealthEvidence& scan, bool& impossible) const;
  /// Fitness and inlier share far from the recent history of ok scans.
  std::string historyProblems(const HealthEvidence& scan) const;
  void remember(const HealthEvidence& scan);

  HealthConfig config_;
  double max_fitness_m2_;
  /// The latest ok scans' registrations, oldest first: the fitness of those away from the
  /// keyframes' viewpoints, the inlier share of all.
  std::deque<double> fitness_history_m2_;
  std::deque<double> inlier_share_history_;
  std::optional<double> last_ok_t_s_;
  std::optional<double> previous_t_s_;
  Eigen::Vector3d previous_v_odom_ = Eigen::Vector3d::Zero();
  std::optional<double> lost_since_t_s_;
  /// Since when the track is lost on the current local map (the loss, or the last restart).
  std::optional<double> lost_on_this_map_since_t_s_;
  int ok_in_a_row_ = 0;
  int not_ok_in_a_row_ = 0;
  bool restart_local_map_ = false;
};

}  // namespace taiga::pipeline
