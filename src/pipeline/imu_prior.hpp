#pragma once
// The IMU motion model of the lidar-inertial odometry (motion_prior.hpp, thesis 3.1.1 and paper
// section 2): readings rotated into the body frame, preintegrated between scans for the
// prediction and the IMU factor, propagated at IMU rate for deskewing and the IMU-rate poses, and
// a fixed-lag smoother that fuses IMU and lidar factors.
//
// Start (imu_prior_start.cpp): the IMU readings give attitude and biases
// (imu/initialization.hpp); the second scan registered to the first gives the initial velocity.
// Over the first gravity_alignment_s seconds the lidar poses and the IMU increments then level
// the odom frame once (imu/gravity_alignment.hpp): a start while moving gets its tilt from the
// data rather than from the mean specific force. imu:: and backend:: call the frame they
// integrate in `world`: here it is the odom frame. Internal to the pipeline.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "motion_prior.hpp"
#include "taiga/imu/initialization.hpp"
#include "taiga/pipeline/imu_buffer.hpp"

namespace taiga::pipeline {

/// T_odom_body of an IMU state.
lie::SE3 poseOf(const imu::NavState& state);

class ImuPrior final : public MotionPrior {
 public:
  ImuPrior(const OdometryConfig& config, const RigConfig& rig, const ScanPreparation& preparation,
           const registration::RegistrationConfig& registration);

  void addImu(const ImuSample& sample) override;
  bool start(const io::Scan& scan, std::optional<FirstScan>& first) override;
  std::optional<double> stateTime() const override;
  MotionPrediction predict(const io::Scan& scan) override;
  /// max_jump_m / max_jump_deg. None across a gap in the readings, when the prediction
  /// is the constant-velocity one, nor for a second after it: the state the gap left may be off
  /// by degrees, which the lidar must be allowed to correct.
  std::optional<JumpBound> jumpBound() const override;
  MotionUpdate update(const std::optional<backend::PoseMeasurement>& lidar) override;
  bool levelled() const override { return levelled_; }
  const std::string& initializationNote() const override { return initialization_note_; }
  /// Exp(-[theta; 0]): turns the estimated gravity back to -z (backend/state_blocks.hpp).
  lie::SO3 R_level_odom() const override {
    const Eigen::Vector2d tilt = smoother_.tilt();
    return lie::SO3::Exp(Eigen::Vector3d(-tilt.x(), -tilt.y(), 0.0));
  }
  /// Forgets the state and starts again from the next two scans (attitude from the last second of
  /// readings, velocity from the scans' registration), at T_odom_body's position and heading.
  bool restart(const lie::SE3& T_odom_body) override;

 private:
  /// Attitude and biases from the IMU readings, and the time the state starts at.
  std::pair<imu::InitialState, double> initialAttitude(const io::Scan& first);
  /// The first scan's state from the IMU's attitude and the velocity between the first two.
  FirstScan initialize(const io::Scan& first, const io::Scan& second);
  /// A pose for the gravity alignment; levels the frame when its span is covered.
  std::optional<lie::SE3> collectForAlignment(double t_s, const lie::SE3& T_unlevelled_body,
                                              const imu::Preintegrator* increment);
  /// Levels the frame with the collected poses; returns T_levelled_unlevelled, or none when the
  /// alignment is not trusted (the IMU's attitude is kept).
  std::optional<lie::SE3> levelFrame();
  /// The readings of the last kRestartAttitudeWindow_s before t_s.
  std::vector<ImuSample> recentReadings(double t_s) const;
  /// The twist from the state before the latest to the latest, per second ([rho; theta], body
  /// frame; zero when they share a time).
  lie::Vector6 twistPerS() const;
  /// Across a gap in the readings: the pose at t_s from the twist between the last two states.
  lie::SE3 constantVelocityAt(double t_s) const;
  /// Across a gap in the readings: the IMU factor from the latest state to t_to_s of that twist's
  /// rotation and a constant velocity.
  imu::Preintegrator constantVelocityIncrement(double t_to_s, const imu::ImuNoise& noise) const;

  OdometryConfig config_;
  lie::SO3 R_body_imu_;
  const ScanPreparation& preparation_;
  const registration::RegistrationConfig& registration_;
  Eigen::Vector3d gravity_odom_;
  ImuBuffer imu_;                            ///< readings in the body frame
  std::optional<StampedPose> state_before_;  ///< the state before the latest one
  std::optional<double> last_gap_end_s_;     ///< the end of the last scan predicted across a gap
  backend::OdometrySmoother smoother_;
  std::optional<io::Scan> first_scan_;  ///< held until the second scan arrives
  /// Set by restart(): where the next start places the body (position and heading).
  std::optional<lie::SE3> restart_T_odom_body_;
  Eigen::Vector2d restart_tilt_ = Eigen::Vector2d::Zero();  ///< the odom frame's at the restart
  /// The scan last predicted: its end time and the increment since the previous state.
  double predicted_t_s_ = 0.0;
  std::optional<imu::Preintegrator> preintegrated_;
  std::string initialization_note_;
  bool levelled_ = false;
  std::vector<double> alignment_times_;
  std::vector<lie::SE3> alignment_poses_;
  std::vector<imu::Preintegrator> alignment_increments_;
};

}  // namespace taiga::pipeline
