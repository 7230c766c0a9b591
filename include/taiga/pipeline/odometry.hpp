#pragma once
// The lidar-inertial odometry of thesis 3.1.1 and paper section 2 ("Robotics Approach in Mobile
// Laser Scanning"; "Real-time lidar-inertial positioning and mapping for forestry automation"),
// one scan at a time, in the continuous `odom` frame (docs/frames.md). The steps of addScan():
//   1. predict the body's motion since the previous state (motion prior: IMU preintegration,
//      or constant velocity without an IMU)
//   2. deskew: the scan moved into the body frame at its end time with the poses predicted over
//      its sweep (thesis Eq. 34-35); returns outside the range limits or in the rig's boxes
//      dropped
//   3. voxel filter -> registration source
//   4. register the source to the local map from the prediction (NDT, D2D-NDT or GICP)
//   5. judge the registration: rejected, inflated (degenerate) or used with the fitness-scaled
//      covariance (thesis Eq. 36)
//   6. fuse: the motion prior's state with the lidar factor (IMU: fixed-lag smoothing of the
//      IMU and lidar factors -> pose, velocity, biases)
//   7. health (health_monitor.hpp: ok, degraded or lost, against fixed limits and the run's own
//      recent history), then the keyframe test (thesis Eq. 37): an ok scan joins the local map
//
// With an IMU the odom frame is levelled once, gravity_alignment_s into the run (motion_prior.hpp):
// the scan that levels it carries T_odom_unlevelled, and the earlier outcomes are in the
// unlevelled start frame. SlamSystem holds them until then, so nothing past it sees that frame.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "taiga/core/box.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/core/rig_config.hpp"
#include "taiga/core/sensor_samples.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/imu/preintegration.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/pipeline/local_map.hpp"
#include "taiga/registration/registration.hpp"

namespace taiga::pipeline {

class HealthMonitor;
class WideBasin;
class MotionPrior;
class ScanPreparation;
struct FirstScan;
struct MotionPrediction;

/// What happened to the lidar factor of a scan.
enum class LidarFactor { kFirstScan, kUsed, kInflated, kRejected };
const char* lidarFactorName(LidarFactor factor);

/// The odometry's judgement of a scan (docs/odometry.md, "Health"): ok, degraded (a problem, but
/// the track holds: the scan does not enter the map) or lost (no scan ok for longer than
/// odometry.health.lost_after_s, an impossible state, or not yet recovered from either).
enum class ScanStatus { kOk, kDegraded, kLost };
const char* scanStatusName(ScanStatus status);

struct ScanHealth {
  ScanStatus status = ScanStatus::kOk;
  std::string reason;  ///< why not ok; for an ok scan after a lost stretch, that it recovered
};

/// Milliseconds per stage of one scan (timing.csv).
struct ScanTiming {
  double deskew_ms = 0.0;  ///< prediction and deskew
  double filter_ms = 0.0;
  double registration_ms = 0.0;
  double optimization_ms = 0.0;  ///< judging the registration and fusing it
  double map_ms = 0.0;
  double total_ms = 0.0;
};

struct ScanOutcome {
  std::uint64_t scan_index = 0;
  double t_s = 0.0;  ///< the state's time: the scan's end
  lie::SE3 T_odom_body;
  Eigen::Vector3d v_odom = Eigen::Vector3d::Zero();
  imu::ImuBias bias;
  /// T_odom_body's covariance [dp (odom frame, m); dtheta (body frame, rad)] (MotionState).
  std::optional<lie::Matrix6> covariance;
  LidarFactor lidar = LidarFactor::kFirstScan;
  std::string lidar_note;  ///< why a factor was rejected or inflated
  registration::RegistrationResult registration;
  /// How far the registration moved the body from the motion prior's prediction (translation m,
  /// rotation deg); 0 without a registration.
  double innovation_m = 0.0, innovation_deg = 0.0;
  /// The longest stretch without IMU readings from the previous state to the scan's end, s.
  double imu_gap_s = 0.0;
  std::size_t source_points = 0;
  /// The registration's source: the deskewed scan in the body frame at t_s, voxel-filtered
  /// (what a viewer shows as the current scan).
  std::shared_ptr<const PointCloud> source_cloud_in_body;
  ScanHealth health;
  /// The local map segment the scan belongs to: 0, and one more each time the odometry gave up
  /// a lost local map and started a new one.
  std::uint64_t map_segment = 0;
  /// The keyframe this scan became (0, 1, ... in the order the odometry makes them; the
  /// keyframe store's ids), and its full deskewed scan in the body frame at t_s.
  std::optional<std::uint64_t> keyframe_id;
  std::optional<PointCloud> keyframe_cloud_in_body;
  /// IMU-rate poses T_odom_body after the previous state up to t_s (propagated, as published in
  /// real time).
  std::vector<StampedPose> imu_rate_poses;
  /// Set once, on the scan that levelled the odom frame: the earlier outcomes' poses are in the
  /// unlevelled start frame, and T_odom_unlevelled * pose re-expresses them.
  std::optional<lie::SE3> T_odom_unlevelled;
  ScanTiming timing;
};

class Odometry {
 public:
  /// `lidar_only`: constant-velocity prediction and deskew, no IMU (MotionPrior).
  Odometry(const OdometryConfig& config, const RigConfig& rig, bool lidar_only);
  ~Odometry();
  Odometry(const Odometry&) = delete;
  Odometry& operator=(const Odometry&) = delete;

  /// IMU readings, in time order, in the IMU frame (rotated into the body frame here).
  void addImu(const ImuSample& sample);
  /// One scan: the outcomes it completes, oldest first. None while the IMU has not yet covered
  /// the initialization window; the first scan's and the second's together once it has.
  std::vector<ScanOutcome> addScan(const io::Scan& scan);

  /// Boxes around moving parts of the rig (a harvester's boom), per scan, in the body frame:
  /// returns inside the boxes of a scan's time span are dropped.
  void setMovingBoxes(MovingBoxes boxes_body);
  bool lidarOnly() const { return lidar_only_; }
  /// True once the odom frame is final: levelled, or with no levelling to wait for (alignment
  /// off, lidar-only).
  bool odomFrameFinal() const;
  /// Moves the local map's keyframes to `T_odom_keyframe_at(id, T_odom_keyframe)` and
  /// rebuilds it, e.g. in the shape the mapping graph gave them after a loop closure
  /// (MappingConfig::correct_odometry). The state stays. Between scans.
  void reposeLocalMap(
      const std::function<lie::SE3(std::uint64_t id, const lie::SE3& T_odom_keyframe)>&
          T_odom_keyframe_at) {
    local_map_.repose(T_odom_keyframe_at);
  }
  const std::string& initializationNote() const;
  /// The rotation that levels the odom frame by the odometry's estimate of its tilt against
  /// gravity (identity without an IMU, or with odometry.gravity_tilt_sigma_deg 0).
  lie::SO3 R_level_odom() const;
  /// The local map the scans are registered to (between scans, on the odometry's thread).
  const LocalMap& localMap() const { return local_map_; }

 private:
  std::optional<ScanOutcome> processScan(const io::Scan& scan);
  ScanOutcome firstScanOutcome(FirstScan&& first);
  /// Registration to the local map of the scan ending at t_s, from the prediction and, when
  /// that looks wrong without an IMU or has dead-reckoned for long with one, from the wide
  /// basin's other starts too.
  /// A scan as the registration takes it, in the body frame.
  struct RegistrationSource {
    /// Voxel-filtered: NDT's and GICP's points, and the fitness's.
    const std::vector<Eigen::Vector3d>& points;
    /// Before the voxel filter: D2D's source cells at each pass's cell edge (the filter's 0.4 m
    /// voxels leave one to three points in a 0.5 m cell, below min_points_per_cell).
    const std::vector<Eigen::Vector3d>& unfiltered;
  };
  registration::RegistrationResult registerToMap(const RegistrationSource& source,
                                                 const MotionPrediction& prediction, double t_s);
  /// The local map's NDT passes, coarse to fine: with a coarse first pass after a
  /// constant-velocity prediction, when the map's own cells are only fine (with an IMU).
  std::vector<const registration::NdtTarget*> ndtPasses(bool constant_velocity) const;
  /// One registration from one guess through these NDT passes (unused by GICP), with its fitness.
  registration::RegistrationResult alignToMap(
      const RegistrationSource& source, const lie::SE3& guess_T_odom_body,
      const std::vector<const registration::NdtTarget*>& ndt_passes) const;
  /// How far T_odom_body is from the last keyframe by the keyframe rule (distance plus
  /// keyframe_rotation_weight_m_per_rad times the rotation), m; infinite before the first.
  double fromLastKeyframe_m(const lie::SE3& T_odom_body) const;
  /// Takes the scan's full cloud: a keyframe keeps it in its outcome.
  void maybeAddKeyframe(ScanOutcome& outcome, PointCloud&& cloud_in_body);
  void judgeHealth(ScanOutcome& outcome, bool registered);

  OdometryConfig config_;
  bool lidar_only_;
  registration::RegistrationConfig registration_;
  std::unique_ptr<ScanPreparation> preparation_;
  std::unique_ptr<MotionPrior> motion_;
  LocalMap local_map_;
  std::unique_ptr<HealthMonitor> health_;
  /// Without an IMU whenever the registration looks poor; with one after
  /// kImuBlindBeforeWideBasin_s without an ok scan.
  std::unique_ptr<WideBasin> wide_basin_;
  static constexpr double kImuBlindBeforeWideBasin_s = 1.0;
  std::uint64_t map_segment_ = 0;
  /// Set when the local map restarted and the motion model with it: this scan is no keyframe.
  bool motion_restarted_ = false;
  std::optional<lie::SE3> last_keyframe_T_odom_body_;
  std::uint64_t keyframes_made_ = 0;
};

}  // namespace taiga::pipeline
