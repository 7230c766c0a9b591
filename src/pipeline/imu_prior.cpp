#include "imu_prior.hpp"

#include <algorithm>

#include "constant_velocity_prior.hpp"
#include "taiga/core/log.hpp"
#include "taiga/imu/propagation.hpp"

namespace taiga::pipeline {
namespace {

/// IMU readings needed before the first scan is used, s.
constexpr double kInitializationWindow_s = 0.5;
/// Readings kept before the latest state, s: a restart takes its attitude from them.
constexpr double kRestartAttitudeWindow_s = 1.0;
/// The IMU noise over a stretch without readings: 1-sigma 3 m/s and 0.3 rad over a second, an
/// IMU factor that leaves the lidar to place the body (tens of times weaker than its 1 cm).
constexpr double kGapAccelNoise = 3.0;  // m/s^2/sqrt(Hz)
constexpr double kGapGyroNoise = 0.3;   // rad/s/sqrt(Hz)

}  // namespace

lie::SE3 poseOf(const imu::NavState& state) { return lie::SE3(state.R_world_body, state.p_world); }

std::unique_ptr<MotionPrior> makeMotionPrior(bool lidar_only, const OdometryConfig& config,
                                             const RigConfig& rig,
                                             const ScanPreparation& preparation,
                                             const registration::RegistrationConfig& registration) {
  if (lidar_only) return std::make_unique<ConstantVelocityPrior>();
  return std::make_unique<ImuPrior>(config, rig, preparation, registration);
}

ImuPrior::ImuPrior(const OdometryConfig& config, const RigConfig& rig,
                   const ScanPreparation& preparation,
                   const registration::RegistrationConfig& registration)
    : config_(config),
      R_body_imu_(rig.T_body_imu.rotation()),
      preparation_(preparation),
      registration_(registration),
      gravity_odom_(0.0, 0.0, -config.imu.gravity_mps2),
      smoother_({.gravity_world = gravity_odom_, .window_states = config.window_states}),
      levelled_(config.gravity_alignment_s <= 0.0) {}

void ImuPrior::addImu(const ImuSample& sample) {
  // Readings in the body frame; the lever arm of an IMU away from the body origin is not modelled
  // (the body frame should be the IMU frame, the default).
  ImuSample in_body = sample;
  in_body.acceleration_imu_mps2 = R_body_imu_ * sample.acceleration_imu_mps2;
  in_body.angular_velocity_imu_radps = R_body_imu_ * sample.angular_velocity_imu_radps;
  if (!imu_.add(in_body))
    logger().debug("IMU reading at {:.6f} s is not after the previous one; ignored", sample.t_s);
}

bool ImuPrior::start(const io::Scan& scan, std::optional<FirstScan>& first) {
  if (smoother_.initialized()) return true;
  if (imu_.empty() || imu_.lastTime() - imu_.firstTime() < kInitializationWindow_s) {
    logger().debug(
        "scan {} at {:.3f} s skipped: waiting for {:.1f} s of IMU readings to initialize",
        scan.index, scan.t_end_s, kInitializationWindow_s);
    return false;
  }
  if (!first_scan_) {
    first_scan_ = scan;  // initialization needs the next scan too
    // The attitude is taken from the readings just before the first scan, not from the start
    // of a recording whose IMU may have run long before the lidar.
    imu_.dropBefore(scan.t_start_s - 1.0);
    return false;
  }
  first = initialize(*first_scan_, scan);
  first_scan_.reset();
  return true;
}

std::vector<ImuSample> ImuPrior::recentReadings(double t_s) const {
  std::vector<ImuSample> recent;
  for (const ImuSample& s : imu_.between(t_s - kRestartAttitudeWindow_s, t_s))
    if (s.t_s >= t_s - kRestartAttitudeWindow_s) recent.push_back(s);  // not the one in force
  return recent;
}

bool ImuPrior::restart(const lie::SE3& T_odom_body) {
  // Within a gap in the readings there is no attitude to start from: the state goes on.
  if (!smoother_.initialized() ||
      recentReadings(smoother_.latest().t_s).size() < imu::kMinInitializationReadings)
    return false;
  restart_tilt_ = smoother_.tilt();  // the odom frame's, which the restart keeps
  smoother_.reset();
  state_before_.reset();
  first_scan_.reset();
  preintegrated_.reset();
  restart_T_odom_body_ = T_odom_body;
  alignment_times_.clear();  // a start not yet levelled collects its poses again
  alignment_poses_.clear();
  alignment_increments_.clear();
  return true;
}

std::optional<double> ImuPrior::stateTime() const {
  if (!smoother_.initialized()) return std::nullopt;
  return smoother_.latest().t_s;
}

MotionPrediction ImuPrior::predict(const io::Scan& scan) {
  const backend::StateEstimate previous = smoother_.latest();
  MotionPrediction prediction;
  // Across a gap in the readings (odometry.health.max_imu_gap_s) the preintegration could only
  // hold or interpolate the readings around it, and a handheld's sway changes its rate within a
  // tenth of a second: the scan is predicted and deskewed with the twist of the last two states
  // instead, the IMU factor is that twist's (constantVelocityIncrement) with its noise raised to
  // what it can still tell, and the lidar carries the state through. Holding the last reading
  // lost a walk within 0.5 s.
  prediction.imu_gap_s = imu_.longestGap(previous.t_s, scan.t_end_s);
  const bool in_gap = prediction.imu_gap_s > config_.health.max_imu_gap_s && state_before_;
  imu::ImuNoise noise = config_.imu;
  if (in_gap) {
    last_gap_end_s_ = scan.t_end_s;
    noise.accel_noise_density = std::max(noise.accel_noise_density, kGapAccelNoise);
    noise.gyro_noise_density = std::max(noise.gyro_noise_density, kGapGyroNoise);
  }
  // The preintegrated increment predicts the pose at the scan's end (and is the IMU factor).
  preintegrated_.emplace(in_gap
                             ? constantVelocityIncrement(scan.t_end_s, noise)
                             : imu_.preintegrate(previous.t_s, scan.t_end_s, previous.bias, noise));
  predicted_t_s_ = scan.t_end_s;
  if (in_gap) {
    prediction.T_odom_body = constantVelocityAt(scan.t_end_s);
    prediction.sweep_T_odom_body =
        sweepPoses(scan, [this](double t_s) { return constantVelocityAt(t_s); });
    prediction.constant_velocity = true;
    return prediction;
  }
  prediction.T_odom_body =
      poseOf(preintegrated_->predict(previous.state, previous.bias, smoother_.gravityWorld()));
  // Propagation at IMU rate over the sweep (from its start when it began before the state).
  const double t_from_s = std::min(previous.t_s, scan.t_start_s);
  const auto states = imu::propagateThrough(previous.state, previous.t_s, scan.t_end_s,
                                            imu_.signalOver(t_from_s, scan.t_end_s), previous.bias,
                                            smoother_.gravityWorld());
  for (std::size_t k = 1; k < states.size(); ++k)
    prediction.imu_rate_poses.push_back({states[k].t_s, poseOf(states[k].state)});
  prediction.sweep_T_odom_body = imu::toTrajectory(states);
  return prediction;
}

lie::Vector6 ImuPrior::twistPerS() const {
  const backend::StateEstimate& latest = smoother_.latest();
  const double dt_s = latest.t_s - state_before_->t_s;
  if (!(dt_s > 0.0)) return lie::Vector6::Zero();
  return (state_before_->pose.inverse() * poseOf(latest.state)).Log() / dt_s;
}

lie::SE3 ImuPrior::constantVelocityAt(double t_s) const {
  const backend::StateEstimate& latest = smoother_.latest();
  return poseOf(latest.state) * lie::SE3::Exp(twistPerS() * (t_s - latest.t_s));
}

imu::Preintegrator ImuPrior::constantVelocityIncrement(double t_to_s,
                                                       const imu::ImuNoise& noise) const {
  // The readings of a body turning at the twist's rate with a constant velocity: the specific
  // force is gravity's reaction in the body frame, f = R(t)^T (-g_world), R(t) = R_latest
  // Exp(omega t). The readings held over the gap instead carried the gravity of the attitude at
  // its start, turned by the sway since: metres per second squared off, which pulled the velocity
  // by up to 2 m/s and the pose 0.4 m from its lidar registrations after a 1 s gap (`typical`
  // handheld walk; docs/odometry.md, Health).
  const backend::StateEstimate& latest = smoother_.latest();
  constexpr double kStep_s = 0.005;
  const Eigen::Vector3d omega_radps = twistPerS().tail<3>();
  const Eigen::Vector3d up_specific_force = -smoother_.gravityWorld();
  imu::Preintegrator increment(latest.bias, noise);
  for (double t_s = latest.t_s; t_s < t_to_s; t_s += kStep_s) {
    const double step_s = std::min(kStep_s, t_to_s - t_s);
    const lie::SO3 R_odom_body =
        latest.state.R_world_body * lie::SO3::Exp(omega_radps * (t_s + 0.5 * step_s - latest.t_s));
    // Readings carry the bias the preintegration takes off again.
    increment.integrate(R_odom_body.inverse() * up_specific_force + latest.bias.accel_mps2,
                        omega_radps + latest.bias.gyro_radps, step_s);
  }
  return increment;
}

std::optional<JumpBound> ImuPrior::jumpBound() const {
  if (last_gap_end_s_ && predicted_t_s_ <= *last_gap_end_s_ + 1.0) return std::nullopt;
  return JumpBound{.max_m = config_.max_jump_m, .max_deg = config_.max_jump_deg};
}

MotionUpdate ImuPrior::update(const std::optional<backend::PoseMeasurement>& lidar) {
  const backend::StateEstimate before = smoother_.latest();
  state_before_ = StampedPose{before.t_s, poseOf(before.state)};
  const backend::StateEstimate estimate =
      smoother_.addState(predicted_t_s_, *preintegrated_, lidar);
  imu_.dropBefore(estimate.t_s - kRestartAttitudeWindow_s);
  MotionUpdate update;
  update.state = {poseOf(estimate.state), estimate.state.v_world, estimate.bias,
                  estimate.covariance.topLeftCorner<6, 6>()};
  if (!levelled_) {
    // The lidar's own pose where registration worked: the alignment must not see the IMU's
    // (wrongly levelled) prediction; the fused pose otherwise.
    update.T_odom_unlevelled = collectForAlignment(
        estimate.t_s, lidar ? lidar->T_world_body : update.state.T_odom_body, &*preintegrated_);
    if (update.T_odom_unlevelled) {
      state_before_.reset();  // in the unlevelled frame
      const backend::StateEstimate levelled = smoother_.latest();
      update.state.T_odom_body = poseOf(levelled.state);
      update.state.v_odom = levelled.state.v_world;
      update.state.covariance = levelled.covariance.topLeftCorner<6, 6>();
    }
  }
  preintegrated_.reset();
  return update;
}

}  // namespace taiga::pipeline
