// The IMU model's start: initial state from the IMU and the first two scans, and the one-time
// levelling of the odom frame by gravity alignment (imu_prior.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "imu_prior.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/log.hpp"
#include "taiga/imu/gravity_alignment.hpp"
#include "taiga/imu/initialization.hpp"
#include "taiga/imu/propagation.hpp"
#include "taiga/preprocess/voxel_filter.hpp"

namespace taiga::pipeline {
std::pair<imu::InitialState, double> ImuPrior::initialAttitude(const io::Scan& first) {
  // With an IMU orientation output the attitude is that of one instant, the last reading used:
  // the state starts there, at the last reading before the first scan. A walking rig pitches by
  // degrees within a tenth of a second, so a later reading's attitude used at the scan's start
  // would tilt the whole start of the map (1.3 % end-point drift on a 15 s walk, 0.1 % without).
  // Without orientation the tilt is a mean over the readings, and more readings average better.
  // A restart's buffer starts with a reading from before the loss (the one in force then): its
  // attitude comes from the last second's readings alone, which restart() made sure exist.
  const std::vector<ImuSample> before_first = restart_T_odom_body_
                                                  ? recentReadings(first.t_start_s)
                                                  : imu_.between(imu_.firstTime(), first.t_start_s);
  const bool before_suffices =
      before_first.size() >= imu::kMinInitializationReadings &&
      before_first.back().t_s <= first.t_start_s &&
      (restart_T_odom_body_ || before_first.back().orientation.has_value());
  const imu::InitialState init = imu::initializeFromImu(before_suffices ? before_first : imu_.all(),
                                                        {.gravity_mps2 = config_.imu.gravity_mps2});
  if (restart_T_odom_body_) {
    logger().info("odometry restarted at {:.3f} s, IMU attitude {}", first.t_start_s,
                  init.description);
  } else {
    initialization_note_ = init.description;
    logger().info("IMU initialization, {}", init.description);
  }
  return {init, before_suffices ? init.t_s : first.t_start_s};
}

FirstScan ImuPrior::initialize(const io::Scan& first, const io::Scan& second) {
  const auto [init, t_init_s] = initialAttitude(first);

  // The sweep of the first scan smears by the distance travelled during it (0.13 m at a walking
  // pace), and the local map starts from it: deskewing it needs the velocity, which the IMU alone
  // does not give while moving. Registering the second scan to the first gives it (the mean
  // velocity between the scans' ends); two rounds, the second with both scans deskewed with it.
  imu::NavState at_first_start = init.state;
  at_first_start.p_world.setZero();
  at_first_start.v_world.setZero();
  const bool restarting = restart_T_odom_body_.has_value();
  const lie::SO3 R_odom_level =
      lie::SO3::Exp(Eigen::Vector3d(restart_tilt_.x(), restart_tilt_.y(), 0.0));
  const Eigen::Vector3d gravity_odom = restarting ? R_odom_level * gravity_odom_ : gravity_odom_;
  if (restarting) {
    // The tilt is the readings', against gravity in the odom frame as tilted as before; the
    // position and heading are where dead reckoning had the body: the mapping graph then finds
    // the new map segment in the map (docs/odometry.md, Health).
    const lie::SO3 R_odom_body = R_odom_level * init.state.R_world_body;
    const lie::SO3& R_was = restart_T_odom_body_->rotation();
    at_first_start.R_world_body =
        lie::SO3::fromRollPitchYaw(0.0, 0.0, R_was.yaw() - R_odom_body.yaw()) * R_odom_body;
    at_first_start.p_world = restart_T_odom_body_->translation();
    restart_T_odom_body_.reset();
  }
  const double dt = second.t_end_s - first.t_end_s;
  imu::NavState at_first_end;
  PointCloud first_in_body;
  // The odometry's NDT passes, coarse to fine, scoring all neighbouring cells (kDirect7): the
  // two scans have no motion estimate between them yet.
  registration::NdtConfig ndt = registration_.ndt;
  ndt.search = registration::NeighbourSearch::kDirect7;
  for (int round = 0; round < 2; ++round) {
    const std::vector<ImuSample> readings = imu_.signalOver(t_init_s, second.t_end_s);
    const auto over_first = imu::propagateThrough(at_first_start, t_init_s, first.t_end_s, readings,
                                                  init.bias, gravity_odom);
    at_first_end = over_first.back().state;
    first_in_body = preparation_.deskewedInBody(first, imu::toTrajectory(over_first));
    const auto over_second = imu::propagateThrough(at_first_end, first.t_end_s, second.t_end_s,
                                                   readings, init.bias, gravity_odom);
    const PointCloud second_in_body =
        preparation_.deskewedInBody(second, imu::toTrajectory(over_second));
    std::vector<Eigen::Vector3d> target_in_odom = preparation_.localMapPoints(first_in_body);
    const lie::SE3 T_odom_first = poseOf(at_first_end);
    for (Eigen::Vector3d& p : target_in_odom) p = T_odom_first * p;
    const registration::RegistrationResult r = registration::alignNdt(
        preprocess::voxelFilter(second_in_body, config_.voxel_size_m,
                                preprocess::voxelRepresentative(config_.voxel_point))
            .positions,
        target_in_odom, poseOf(over_second.back().state), ndt);
    if (r.num_inliers == 0 || !std::isfinite(r.hessian_condition)) {
      logger().warn(
          "initial velocity: the second scan did not register to the first ({}); starting from "
          "rest",
          r.reason);
      break;
    }
    const Eigen::Vector3d v_odom =
        (r.T_target_source.translation() - T_odom_first.translation()) / dt;
    // The first sweep's start velocity, from the mean velocity between the scan ends.
    at_first_start.v_world = v_odom;
  }
  logger().info("initial velocity {:.2f} m/s from the first two scans",
                at_first_start.v_world.norm());
  initialization_note_ += fmt::format("; initial speed {:.2f} m/s from the first two scans",
                                      at_first_start.v_world.norm());

  backend::StateEstimate estimate;
  estimate.t_s = first.t_end_s;
  estimate.state = at_first_end;
  estimate.bias = init.bias;
  estimate.covariance = init.covariance;
  estimate.covariance.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() * 0.2 * 0.2;
  if (!levelled_) {
    // Until the levelling, the odom frame's gravity is off by the start's tilt error (degrees
    // while moving: 1 m/s^2 at 6 deg). A loose accelerometer bias absorbs it at once, so the
    // smoother's attitude follows the lidar instead of bending the map towards the wrong
    // gravity; the alignment then estimates the bias afresh (levelFrame).
    constexpr double kUnlevelledAccelBiasSigma_mps2 = 1.0;
    estimate.covariance.block<3, 3>(9, 9) = Eigen::Matrix3d::Identity() *
                                            kUnlevelledAccelBiasSigma_mps2 *
                                            kUnlevelledAccelBiasSigma_mps2;
  }
  // A frame levelled by the IMU's attitude alone keeps estimating its tilt from the start; an
  // unlevelled one lets the loose bias absorb its gravity error until the levelling.
  smoother_.initialize(estimate, levelled_ ? config_.gravity_tilt_sigma_deg * kRadPerDeg : 0.0,
                       restarting ? restart_tilt_ : Eigen::Vector2d::Zero());

  FirstScan out{.index = first.index,
                .t_s = first.t_end_s,
                .state = {poseOf(estimate.state), estimate.state.v_world, estimate.bias},
                .cloud_in_body = std::move(first_in_body)};
  if (!levelled_) collectForAlignment(out.t_s, out.state.T_odom_body, nullptr);
  return out;
}

std::optional<lie::SE3> ImuPrior::collectForAlignment(double t_s, const lie::SE3& T_unlevelled_body,
                                                      const imu::Preintegrator* increment) {
  alignment_times_.push_back(t_s);
  alignment_poses_.push_back(T_unlevelled_body);
  if (increment) alignment_increments_.push_back(*increment);
  if (alignment_times_.back() - alignment_times_.front() < config_.gravity_alignment_s)
    return std::nullopt;
  return levelFrame();
}

std::optional<lie::SE3> ImuPrior::levelFrame() {
  // The bias the unlevelled smoother held is mostly the frame's tilt error, so the alignment
  // takes the increments at a zero bias and estimates gravity and the bias together. Over 2 s a
  // horizontal bias and a tilt look alike and this prior decides between them (a wider one
  // helped the `harsh` rig and hurt `typical` ones: docs/odometry.md, Height).
  constexpr double kAlignmentAccelBiasSigma_mps2 = 0.3;
  const imu::GravityAlignment a =
      imu::alignGravity(alignment_poses_, alignment_increments_, config_.imu.gravity_mps2,
                        kAlignmentAccelBiasSigma_mps2);
  alignment_times_.clear();
  alignment_poses_.clear();
  alignment_increments_.clear();
  levelled_ = true;
  // A free estimate of |g| far from gravity means the poses and the IMU disagree (bad
  // registrations, a wrong time offset): keep the IMU attitude rather than trust it.
  if (std::abs(a.estimated_magnitude_mps2 - config_.imu.gravity_mps2) >
      0.05 * config_.imu.gravity_mps2) {
    logger().warn(
        "gravity alignment over the first {:.1f} s found |g| = {:.2f} m/s^2; keeping the IMU's "
        "attitude",
        config_.gravity_alignment_s, a.estimated_magnitude_mps2);
    return std::nullopt;
  }
  const backend::StateEstimate current = smoother_.latest();
  backend::StateEstimate levelled = current;
  levelled.state.R_world_body = a.R_levelled_world * current.state.R_world_body;
  levelled.state.p_world = a.R_levelled_world * current.state.p_world;
  levelled.state.v_world = a.R_levelled_world * a.v_world.back();
  // Tilt and velocity now come from the alignment; position and heading keep fixing the gauge.
  levelled.covariance = current.covariance;
  levelled.covariance.block<15, 6>(0, 0).setZero();
  levelled.covariance.block<6, 15>(0, 0).setZero();
  levelled.covariance.block<3, 9>(6, 6).setZero();
  levelled.covariance.block<9, 3>(6, 6).setZero();
  const double tilt_sigma = 0.3 * kRadPerDeg;
  levelled.covariance.diagonal().head<9>() << Eigen::Vector3d::Constant(1e-6),
      tilt_sigma * tilt_sigma, tilt_sigma * tilt_sigma, 1e-6,
      Eigen::Vector3d::Constant(0.05 * 0.05);
  // The accelerometer bias from the alignment, with the start's prior sigma.
  levelled.bias.accel_mps2 = a.accel_bias_mps2;
  levelled.covariance.block<3, 15>(9, 0).setZero();
  levelled.covariance.block<15, 3>(0, 9).setZero();
  levelled.covariance.block<3, 3>(9, 9) =
      Eigen::Matrix3d::Identity() * imu::kStartAccelBiasSigma_mps2 * imu::kStartAccelBiasSigma_mps2;
  smoother_.initialize(levelled, config_.gravity_tilt_sigma_deg * kRadPerDeg);
  const double tilt_deg =
      std::acos(std::clamp(a.gravity_world.normalized().z() * -1.0, -1.0, 1.0)) / kRadPerDeg;
  logger().info(
      "gravity alignment: the initial attitude was off by {:.2f} deg of tilt; odom frame levelled "
      "(|g| estimated {:.3f} m/s^2, accelerometer bias {:.3f} {:.3f} {:.3f} m/s^2)",
      tilt_deg, a.estimated_magnitude_mps2, a.accel_bias_mps2.x(), a.accel_bias_mps2.y(),
      a.accel_bias_mps2.z());
  initialization_note_ +=
      fmt::format("; levelled after {:.1f} s by {:.2f} deg", config_.gravity_alignment_s, tilt_deg);
  return lie::SE3(a.R_levelled_world, Eigen::Vector3d::Zero());
}

}  // namespace taiga::pipeline
