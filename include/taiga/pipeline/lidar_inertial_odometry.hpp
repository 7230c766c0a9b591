#pragma once
// The lidar-inertial odometry of thesis 3.1.1 and paper section 2, one scan at a time. The steps
// of addScan() are numbered as in DESIGN.md's data flow:
//   1. preintegrate the IMU since the previous state; predict the pose at the scan's end
//   2. deskew: poses over the sweep from IMU propagation, the scan moved into the body frame at
//      its end time (thesis Eq. 34-35); returns closer/farther than the range limits dropped
//   3. voxel filter (0.4 m) -> registration source
//   4. register the source to the local map from the prediction (NDT, D2D-NDT or GICP)
//   5. judge the registration: rejected (did not converge, poor fitness, jump against the IMU
//      prediction), inflated (degenerate Hessian) or used with the fitness-scaled covariance
//      (thesis Eq. 36)
//   6. odometry graph: IMU factor + lidar factor, fixed-lag smoothing -> pose, velocity, biases
//   7. keyframe test (thesis Eq. 37): the deskewed scan joins the local map in the world frame
//
// Before the first scan the IMU readings initialize attitude and biases
// (imu/initialization.hpp). Over the first gravity_alignment_s seconds the lidar poses and the
// IMU increments then level the world frame (imu/gravity_alignment.hpp): a start while moving
// gets its tilt from the data rather than from the mean specific force; the correction is
// reported once in ScanOutcome::world_correction, and everything so far is re-expressed with it.

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "taiga/backend/odometry_smoother.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/core/rig_config.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/imu/preintegration.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/pipeline/imu_buffer.hpp"
#include "taiga/pipeline/local_map.hpp"
#include "taiga/registration/result.hpp"

namespace taiga::pipeline {

/// What happened to the lidar factor of a scan.
enum class LidarFactor { kFirstScan, kUsed, kInflated, kRejected };
const char* lidarFactorName(LidarFactor factor);

/// Milliseconds per stage of one scan (timing.csv).
struct ScanTiming {
  double deskew_ms = 0.0;
  double filter_ms = 0.0;
  double registration_ms = 0.0;
  double optimization_ms = 0.0;
  double map_ms = 0.0;
  double total_ms = 0.0;
};

struct ScanOutcome {
  std::uint64_t scan_index = 0;
  double t_s = 0.0;  ///< the state's time: the scan's end
  lie::SE3 T_world_body;
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  imu::ImuBias bias;
  LidarFactor lidar = LidarFactor::kFirstScan;
  std::string lidar_note;  ///< why a factor was rejected or inflated
  registration::RegistrationResult registration;
  std::size_t source_points = 0;
  bool keyframe = false;
  /// The full deskewed scan in the body frame at t_s, when this scan became a keyframe.
  std::optional<PointCloud> keyframe_cloud_in_body;
  /// IMU-rate poses after the previous state up to t_s (propagated, as published in real time).
  std::vector<StampedPose> imu_rate_poses;
  /// Set once, when gravity alignment levels the world frame: T_new_old to apply to every pose
  /// and point output before this scan (this scan's outputs are already in the new frame).
  std::optional<lie::SE3> world_correction;
  ScanTiming timing;
};

class LidarInertialOdometry {
 public:
  LidarInertialOdometry(const OdometryConfig& config, const RigConfig& rig);
  ~LidarInertialOdometry();

  /// IMU readings, in time order, in the IMU frame (rotated into the body frame here).
  void addImu(const ImuSample& sample);
  /// One scan; nothing while the IMU has not yet covered the initialization window.
  std::optional<ScanOutcome> addScan(const io::Scan& scan);

  /// Boxes around moving parts of the rig (a harvester's boom), per scan, in the body frame:
  /// returns inside the boxes of a scan's time span are dropped.
  void setMovingBoxes(MovingBoxes boxes_body) { moving_boxes_body_ = std::move(boxes_body); }
  /// Without an IMU: each scan is predicted and deskewed with the constant velocity of the last
  /// two poses and registered to the local map; the world frame is the first scan's body frame
  /// (not levelled). Set before the first scan. The constant-velocity prediction may be off by
  /// decimetres, so registration then runs coarse to fine (OdometryConfig::ndtResolutionsM()).
  void setLidarOnly(bool lidar_only);
  bool lidarOnly() const { return lidar_only_; }

  bool initialized() const { return lidar_only_ || smoother_.initialized(); }
  /// The first scan's outcome (its state and keyframe), once, after the scan that initialized.
  std::optional<ScanOutcome> takeFirstOutcome() {
    return std::exchange(first_outcome_, std::nullopt);
  }
  /// True once the world frame is levelled (or when alignment is off).
  bool levelled() const { return levelled_; }
  /// Moves the local map's keyframes to `T_world_keyframe_at(t_s, T_world_keyframe)` and
  /// rebuilds it, e.g. in the shape the mapping graph gave them after a loop closure
  /// (MappingConfig::correct_odometry). The state stays. Between scans.
  void reposeLocalMap(const std::function<lie::SE3(double t_s, const lie::SE3& T_world_keyframe)>&
                          T_world_keyframe_at) {
    local_map_.repose(T_world_keyframe_at);
  }
  const std::string& initializationNote() const { return initialization_note_; }

 private:
  /// The local map's NDT passes, coarse to fine.
  std::vector<double> registrationResolutionsM() const;
  void initialize(const io::Scan& first, const io::Scan& second);
  std::optional<ScanOutcome> addScanLidarOnly(const io::Scan& scan);
  /// The scan's returns within the range limits and outside the rig's boxes, in the lidar frame.
  PointCloud forestPointsInLidar(const io::Scan& scan) const;
  PointCloud deskewScan(const io::Scan& scan, const imu::NavState& state_prev, double t_prev,
                        const imu::ImuBias& bias, std::vector<StampedPose>* imu_rate_poses);
  registration::RegistrationResult registerToMap(const std::vector<Eigen::Vector3d>& source,
                                                 const lie::SE3& guess_T_world_body);
  std::optional<backend::PoseMeasurement> judge(ScanOutcome& outcome, const lie::SE3& predicted,
                                                bool check_jump = true) const;
  void maybeAddKeyframe(ScanOutcome& outcome, const PointCloud& cloud_in_body);
  void collectForAlignment(const ScanOutcome& outcome, const imu::Preintegrator* increment);
  void levelWorld(ScanOutcome& outcome);
  imu::ImuNoise imuNoise() const;

  OdometryConfig config_;
  RigConfig rig_;
  std::vector<OrientedBox> self_boxes_lidar_;  ///< rig.self_boxes_body in the lidar frame
  MovingBoxes moving_boxes_body_;
  bool lidar_only_ = false;
  /// Lidar-only: the last pose and the body-frame twist per second that predicts the next.
  struct ConstantVelocity {
    double t_s = 0.0;
    lie::SE3 T_world_body;
    lie::Vector6 twist_per_s = lie::Vector6::Zero();
  };
  std::optional<ConstantVelocity> constant_velocity_;
  Eigen::Vector3d gravity_world_;
  ImuBuffer imu_;
  backend::OdometrySmoother smoother_;
  LocalMap local_map_;
  std::optional<lie::SE3> last_keyframe_T_world_body_;
  std::string initialization_note_;
  bool levelled_ = false;
  std::optional<io::Scan> first_scan_;  ///< held until the second scan arrives
  std::optional<ScanOutcome>
      first_outcome_;  ///< the first scan's outcome, handed out by takeFirstOutcome()
  std::vector<double> alignment_times_;
  std::vector<lie::SE3> alignment_poses_;
  std::vector<imu::Preintegrator> alignment_increments_;
};

}  // namespace taiga::pipeline
