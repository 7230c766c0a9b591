#pragma once
// Step 1 and 6 of the odometry behind one interface, so that its steps are written once: the
// motion model predicts the body's pose over a scan's sweep and at its end, and fuses the
// lidar's pose measurement into the state. Two models (make with makeMotionPrior):
//   - IMU: preintegration (Forster et al.) and the fixed-lag smoother of backend/; it starts
//     from the IMU's attitude and the first two scans (imu/initialization.hpp) and levels the
//     odom frame once after gravity_alignment_s (imu/gravity_alignment.hpp);
//   - constant velocity, without an IMU: the twist of the last two poses, the registered pose
//     as the state (the odom frame is the first scan's body frame, not levelled).
// Internal to the pipeline.

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scan_preparation.hpp"
#include "taiga/backend/odometry_smoother.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/core/point_cloud.hpp"
#include "taiga/core/rig_config.hpp"
#include "taiga/core/sensor_samples.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/imu/preintegration.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/registration/registration.hpp"

namespace taiga::pipeline {

struct MotionPrediction {
  lie::SE3 T_odom_body;          ///< at the scan's end
  Trajectory sweep_T_odom_body;  ///< poses covering the sweep, for deskewing
  /// Propagated IMU-rate poses after the previous state up to the scan's end (IMU only).
  std::vector<StampedPose> imu_rate_poses;
  /// The longest time without an IMU reading from the previous state to the scan's end (IMU
  /// only), s: beyond odometry.health.max_imu_gap_s the IMU factor over it is weakened and the
  /// scan degraded.
  double imu_gap_s = 0.0;
  /// Predicted by the twist of the last two states (lidar-only, or across a gap in the IMU
  /// readings): off by decimetres and degrees where the body accelerates or sways, so the
  /// registration starts with a coarse pass for its wider basin.
  bool constant_velocity = false;
};

/// Poses over a scan's sweep every 10 ms and at its end, for the deskew's interpolation, from a
/// model of the pose at any time (the constant-velocity predictions).
template <class PoseAt>
Trajectory sweepPoses(const io::Scan& scan, PoseAt T_odom_body_at) {
  constexpr double kStep_s = 0.01;
  Trajectory sweep;
  for (double t = scan.t_start_s; t < scan.t_end_s; t += kStep_s)
    sweep.append(t, T_odom_body_at(t));
  sweep.append(scan.t_end_s, T_odom_body_at(scan.t_end_s));
  return sweep;
}

/// How far a registration may lie from the prediction before it is rejected (the lidar factor's
/// jump test, lidar_factor.hpp).
struct JumpBound {
  double max_m = 0.0;
  double max_deg = 0.0;
};

struct MotionState {
  lie::SE3 T_odom_body;
  Eigen::Vector3d v_odom = Eigen::Vector3d::Zero();
  imu::ImuBias bias;
  /// The pose's covariance, [dp (odom frame, m); dtheta (body frame, rad)]: with an IMU the
  /// smoother's marginal; lidar-only the registration's; none when nothing measured the pose.
  /// Local: relative to the odom frame and its map, it does not grow with drift.
  std::optional<lie::Matrix6> covariance;
};

/// A pose covariance [dp; dtheta (body)] with dp's frame turned by R_new_old.
inline lie::Matrix6 rotatedCovariance(const lie::Matrix6& covariance, const lie::SO3& R_new_old) {
  lie::Matrix6 J = lie::Matrix6::Identity();
  J.topLeftCorner<3, 3>() = R_new_old.matrix();
  return J * covariance * J.transpose();
}

struct MotionUpdate {
  MotionState state;
  /// Set once, when the IMU's gravity alignment levelled the odom frame at this scan: every
  /// earlier pose is in the unlevelled start frame and T_odom_unlevelled re-expresses it. The
  /// state above is already levelled; the local map must start over (its keyframes were deskewed
  /// with the velocity still unknown).
  std::optional<lie::SE3> T_odom_unlevelled;
};

/// The first scan of a model that needs two scans to start (the IMU's initial velocity).
struct FirstScan {
  std::uint64_t index = 0;
  double t_s = 0.0;
  MotionState state;
  PointCloud cloud_in_body;  ///< deskewed, at t_s
};

class MotionPrior {
 public:
  virtual ~MotionPrior() = default;

  /// IMU readings in the IMU frame, in time order; ignored without an IMU.
  virtual void addImu(const ImuSample& sample) = 0;
  /// False while the model waits for data before `scan` can be predicted (IMU: 0.5 s of
  /// readings and a second scan). On the call that starts it, `first` gets the scan held.
  virtual bool start(const io::Scan& scan, std::optional<FirstScan>& first) = 0;
  /// The time of the latest state; none before the first.
  virtual std::optional<double> stateTime() const = 0;
  virtual MotionPrediction predict(const io::Scan& scan) = 0;
  /// How far from the last prediction a registration is suspect, when the prediction is a
  /// yardstick (IMU: good to centimetres over a scan); none for a constant velocity, which
  /// ignores accelerations.
  virtual std::optional<JumpBound> jumpBound() const = 0;
  /// The state at the end of the scan last predicted, with the lidar's measurement of T_odom_body
  /// (none when the registration was rejected or there was no map yet).
  virtual MotionUpdate update(const std::optional<backend::PoseMeasurement>& lidar) = 0;
  /// True once the odom frame is final: levelled, or with no levelling to wait for.
  virtual bool levelled() const = 0;
  virtual const std::string& initializationNote() const = 0;
  /// The rotation that levels the odom frame by the model's estimate of its tilt (identity
  /// when it has none).
  virtual lie::SO3 R_level_odom() const { return {}; }
  /// The track was lost for long and the local map starts over: the state the loss left (its
  /// velocity and tilt) is not to be trusted. True when the model starts again from the next
  /// scans, as at its start, at T_odom_body's position and heading (IMU); false when it goes on.
  virtual bool restart(const lie::SE3& /*T_odom_body*/) { return false; }
};

/// The IMU model, or constant velocity when `lidar_only`. `preparation` and `registration`
/// must outlive it (the IMU's start deskews and registers the first two scans).
std::unique_ptr<MotionPrior> makeMotionPrior(bool lidar_only, const OdometryConfig& config,
                                             const RigConfig& rig,
                                             const ScanPreparation& preparation,
                                             const registration::RegistrationConfig& registration);

}  // namespace taiga::pipeline
