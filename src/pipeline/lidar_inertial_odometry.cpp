#include "taiga/pipeline/lidar_inertial_odometry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "taiga/core/log.hpp"
#include "taiga/imu/gravity_alignment.hpp"
#include "taiga/imu/initialization.hpp"
#include "taiga/imu/propagation.hpp"
#include "taiga/preprocess/crop.hpp"
#include "taiga/preprocess/deskew.hpp"
#include "taiga/preprocess/voxel_filter.hpp"
#include "taiga/registration/kdtree.hpp"

namespace taiga::pipeline {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kDegToRad = std::numbers::pi / 180.0;
/// IMU readings needed before the first scan is used, s.
constexpr double kInitializationWindow_s = 0.5;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

lie::SE3 poseOf(const imu::NavState& state) { return lie::SE3(state.R_world_body, state.p_world); }

}  // namespace

const char* lidarFactorName(LidarFactor factor) {
  switch (factor) {
    case LidarFactor::kFirstScan:
      return "first_scan";
    case LidarFactor::kUsed:
      return "used";
    case LidarFactor::kInflated:
      return "inflated";
    case LidarFactor::kRejected:
      return "rejected";
  }
  return "?";
}

LidarInertialOdometry::LidarInertialOdometry(const OdometryConfig& config, const RigConfig& rig)
    : config_(config),
      rig_(rig),
      gravity_world_(0.0, 0.0, -config.imu.gravity_mps2),
      smoother_({.gravity_world = gravity_world_, .window_states = config.window_states}),
      local_map_(registrationResolutionsM(), config.local_map_voxel_m, config.local_map_keyframes,
                 config.method == "gicp" ? LocalMap::Target::kGicp : LocalMap::Target::kNdt),
      levelled_(config.gravity_alignment_s <= 0.0) {
  const lie::SE3 T_lidar_body = rig_.T_body_lidar.inverse();
  for (const Box& box : rig_.self_boxes_body)
    self_boxes_lidar_.push_back(OrientedBox::fromBox(box).expressedIn(T_lidar_body));
}

LidarInertialOdometry::~LidarInertialOdometry() = default;

void LidarInertialOdometry::setLidarOnly(bool lidar_only) {
  lidar_only_ = lidar_only;
  local_map_.setNdtResolutions(registrationResolutionsM());
}

std::vector<double> LidarInertialOdometry::registrationResolutionsM() const {
  // The IMU predicts within centimetres: the fine cells' basin suffices. The constant-velocity
  // prediction of lidar-only odometry may be off by decimetres: coarse to fine.
  if (lidar_only_) return config_.ndtResolutionsM();
  return {config_.ndt_resolution_m};
}

imu::ImuNoise LidarInertialOdometry::imuNoise() const {
  return {config_.imu.accel_noise_density, config_.imu.gyro_noise_density,
          config_.imu.accel_bias_random_walk, config_.imu.gyro_bias_random_walk};
}

void LidarInertialOdometry::addImu(const ImuSample& sample) {
  if (lidar_only_) return;
  // Readings in the body frame; the lever arm of an IMU away from the body origin is not modelled
  // (the body frame should be the IMU frame, the default).
  ImuSample in_body = sample;
  const lie::SO3& R_body_imu = rig_.T_body_imu.rotation();
  in_body.acceleration_imu_mps2 = R_body_imu * sample.acceleration_imu_mps2;
  in_body.angular_velocity_imu_radps = R_body_imu * sample.angular_velocity_imu_radps;
  if (!imu_.add(in_body))
    logger().debug("IMU reading at {:.6f} s is not after the previous one; ignored", sample.t_s);
}

// The rig is rigid with the body, so a point is tested against the boxes at its own firing time,
// before deskewing: exact for any motion during the sweep.
PointCloud LidarInertialOdometry::forestPointsInLidar(const io::Scan& scan) const {
  const PointCloud in_range =
      preprocess::keepRange(scan.cloud_in_lidar, config_.min_range_m, config_.max_range_m);
  std::vector<OrientedBox> boxes_lidar = self_boxes_lidar_;
  const lie::SE3 T_lidar_body = rig_.T_body_lidar.inverse();
  for (const OrientedBox& box_body : moving_boxes_body_.forScan(scan.t_start_s, scan.t_end_s))
    boxes_lidar.push_back(box_body.expressedIn(T_lidar_body));
  return preprocess::removeInsideBoxes(in_range, boxes_lidar);
}

PointCloud LidarInertialOdometry::deskewScan(const io::Scan& scan, const imu::NavState& state_prev,
                                             double t_prev, const imu::ImuBias& bias,
                                             std::vector<StampedPose>* imu_rate_poses) {
  const double t_from = std::min(t_prev, scan.t_start_s);
  const std::vector<ImuSample> readings = imu_.between(t_from, scan.t_end_s);
  const auto states =
      imu::propagateThrough(state_prev, t_prev, scan.t_end_s, readings, bias, gravity_world_);
  if (imu_rate_poses) {
    for (std::size_t k = 1; k < states.size(); ++k)
      imu_rate_poses->push_back({states[k].t_s, poseOf(states[k].state)});
  }
  return preprocess::deskew(forestPointsInLidar(scan), rig_.T_body_lidar, imu::toTrajectory(states),
                            scan.t_end_s)
      .cloud_in_body;
}

void LidarInertialOdometry::initialize(const io::Scan& first, const io::Scan& second) {
  // With an IMU orientation output the attitude is that of one instant, the last reading used:
  // the state starts there, at the last reading before the first scan. A walking rig pitches by
  // degrees within a tenth of a second, so a later reading's attitude used at the scan's start
  // would tilt the whole start of the map (1.3 % end-point drift on a 15 s walk, 0.1 % without).
  // Without orientation the tilt is a mean over the readings, and more readings average better.
  constexpr std::size_t kMinReadings = 10;  // what initializeFromImu needs
  const std::vector<ImuSample> before_first = imu_.between(imu_.firstTime(), first.t_start_s);
  const bool before_suffices = before_first.size() >= kMinReadings &&
                               before_first.back().t_s <= first.t_start_s &&
                               before_first.back().orientation.has_value();
  const imu::InitialState init = imu::initializeFromImu(before_suffices ? before_first : imu_.all(),
                                                        {.gravity_mps2 = config_.imu.gravity_mps2});
  const double t_init_s = before_suffices ? init.t_s : first.t_start_s;
  initialization_note_ = init.description;
  logger().info("IMU initialization, {}", init.description);

  // The sweep of the first scan smears by the distance travelled during it (0.13 m at a walking
  // pace), and the local map starts from it: deskewing it needs the velocity, which the IMU alone
  // does not give while moving. Registering the second scan to the first gives it (the mean
  // velocity between the scans' ends); two rounds, the second with both scans deskewed with it.
  imu::NavState at_first_start = init.state;
  at_first_start.p_world.setZero();
  at_first_start.v_world.setZero();
  const double dt = second.t_end_s - first.t_end_s;
  imu::NavState at_first_end;
  PointCloud first_in_body;
  for (int round = 0; round < 2; ++round) {
    const std::vector<ImuSample> readings = imu_.between(t_init_s, second.t_end_s);
    const auto over_first = imu::propagateThrough(at_first_start, t_init_s, first.t_end_s, readings,
                                                  init.bias, gravity_world_);
    at_first_end = over_first.back().state;
    first_in_body = preprocess::deskew(forestPointsInLidar(first), rig_.T_body_lidar,
                                       imu::toTrajectory(over_first), first.t_end_s)
                        .cloud_in_body;
    const auto over_second = imu::propagateThrough(at_first_end, first.t_end_s, second.t_end_s,
                                                   readings, init.bias, gravity_world_);
    const PointCloud second_in_body =
        preprocess::deskew(forestPointsInLidar(second), rig_.T_body_lidar,
                           imu::toTrajectory(over_second), second.t_end_s)
            .cloud_in_body;
    std::vector<Eigen::Vector3d> target =
        preprocess::voxelFilter(first_in_body, config_.local_map_voxel_m).positions;
    const lie::SE3 T_world_first = poseOf(at_first_end);
    for (Eigen::Vector3d& p : target) p = T_world_first * p;
    registration::NdtConfig ndt;
    const std::vector<double> resolutions_m = config_.ndtResolutionsM();
    ndt.resolution_m = resolutions_m.back();
    ndt.coarse_resolutions_m.assign(resolutions_m.begin(), resolutions_m.end() - 1);
    const registration::RegistrationResult r = registration::alignNdt(
        preprocess::voxelFilter(second_in_body, config_.voxel_size_m).positions, target,
        poseOf(over_second.back().state), ndt);
    if (r.num_inliers == 0 || !std::isfinite(r.hessian_condition)) {
      logger().warn(
          "initial velocity: the second scan did not register to the first ({}); starting from "
          "rest",
          r.reason);
      break;
    }
    const Eigen::Vector3d v_world =
        (r.T_target_source.translation() - T_world_first.translation()) / dt;
    // The first sweep's start velocity, from the mean velocity between the scan ends.
    at_first_start.v_world = v_world;
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
  smoother_.initialize(estimate);

  ScanOutcome outcome;
  outcome.scan_index = first.index;
  outcome.t_s = first.t_end_s;
  outcome.T_world_body = poseOf(estimate.state);
  outcome.v_world = estimate.state.v_world;
  outcome.bias = estimate.bias;
  outcome.lidar = LidarFactor::kFirstScan;
  if (!levelled_) collectForAlignment(outcome, nullptr);
  maybeAddKeyframe(outcome, first_in_body);
  first_outcome_ = std::move(outcome);
}

std::optional<ScanOutcome> LidarInertialOdometry::addScan(const io::Scan& scan) {
  if (lidar_only_) return addScanLidarOnly(scan);
  if (!initialized()) {
    if (imu_.empty() || imu_.lastTime() - imu_.firstTime() < kInitializationWindow_s) {
      logger().debug(
          "scan {} at {:.3f} s skipped: waiting for {:.1f} s of IMU readings to initialize",
          scan.index, scan.t_end_s, kInitializationWindow_s);
      return std::nullopt;
    }
    if (!first_scan_) {
      first_scan_ = scan;  // initialization needs the next scan too
      // The attitude is taken from the readings just before the first scan, not from the start
      // of a recording whose IMU may have run long before the lidar.
      imu_.dropBefore(scan.t_start_s - 1.0);
      return std::nullopt;
    }
    initialize(*first_scan_, scan);
    first_scan_.reset();
  }
  const auto start = Clock::now();
  const backend::StateEstimate previous = smoother_.latest();
  ScanOutcome outcome;
  outcome.scan_index = scan.index;
  outcome.t_s = scan.t_end_s;
  if (scan.t_end_s <= previous.t_s) {
    logger().warn("scan {} ends at {:.6f} s, not after the previous state at {:.6f} s; skipped",
                  scan.index, scan.t_end_s, previous.t_s);
    return std::nullopt;
  }

  // 1. Preintegrate and predict.
  const imu::Preintegrator preintegrated =
      imu_.preintegrate(previous.t_s, scan.t_end_s, previous.bias, imuNoise());
  const lie::SE3 predicted =
      poseOf(preintegrated.predict(previous.state, previous.bias, gravity_world_));

  // 2. Deskew into the body frame at the scan's end.
  const PointCloud cloud_in_body =
      deskewScan(scan, previous.state, previous.t_s, previous.bias, &outcome.imu_rate_poses);
  outcome.timing.deskew_ms = msSince(start);

  // 3. Voxel filter.
  auto stage = Clock::now();
  const PointCloud source_cloud = preprocess::voxelFilter(cloud_in_body, config_.voxel_size_m);
  outcome.source_points = source_cloud.size();
  outcome.timing.filter_ms = msSince(stage);

  // 4. Register to the local map.
  stage = Clock::now();
  outcome.registration = registerToMap(source_cloud.positions, predicted);
  outcome.timing.registration_ms = msSince(stage);

  // 5. Judge it; 6. optimize the odometry graph.
  stage = Clock::now();
  const std::optional<backend::PoseMeasurement> measurement = judge(outcome, predicted);
  const backend::StateEstimate estimate =
      smoother_.addState(scan.t_end_s, preintegrated, measurement);
  imu_.dropBefore(estimate.t_s);
  outcome.T_world_body = poseOf(estimate.state);
  outcome.v_world = estimate.state.v_world;
  outcome.bias = estimate.bias;
  if (!levelled_) {
    collectForAlignment(outcome, &preintegrated);
    if (alignment_times_.back() - alignment_times_.front() >= config_.gravity_alignment_s)
      levelWorld(outcome);
  }
  outcome.timing.optimization_ms = msSince(stage);

  // 7. Keyframe.
  stage = Clock::now();
  maybeAddKeyframe(outcome, cloud_in_body);
  outcome.timing.map_ms = msSince(stage);
  outcome.timing.total_ms = msSince(start);
  return outcome;
}

// The steps of addScan without the IMU: 1. constant-velocity prediction, 2. deskew with it,
// 3. filter, 4. register, 5. judge (fitness only: a prediction that ignores accelerations is no
// yardstick for jumps), 6. the registered pose or, when rejected, the prediction, 7. keyframe.
std::optional<ScanOutcome> LidarInertialOdometry::addScanLidarOnly(const io::Scan& scan) {
  const auto start = Clock::now();
  ScanOutcome outcome;
  outcome.scan_index = scan.index;
  outcome.t_s = scan.t_end_s;
  const ConstantVelocity last = constant_velocity_.value_or(ConstantVelocity{scan.t_end_s});
  if (constant_velocity_ && scan.t_end_s <= last.t_s) {
    logger().warn("scan {} ends at {:.6f} s, not after the previous one at {:.6f} s; skipped",
                  scan.index, scan.t_end_s, last.t_s);
    return std::nullopt;
  }
  auto predictedAt = [&](double t_s) {
    return last.T_world_body * lie::SE3::Exp(last.twist_per_s * (t_s - last.t_s));
  };
  const lie::SE3 predicted = predictedAt(scan.t_end_s);

  // Poses over the sweep every 10 ms (and at its end) for the deskew's interpolation.
  Trajectory sweep;
  constexpr double kStep_s = 0.01;
  for (double t = scan.t_start_s; t < scan.t_end_s; t += kStep_s) sweep.append(t, predictedAt(t));
  sweep.append(scan.t_end_s, predicted);
  const PointCloud cloud_in_body =
      preprocess::deskew(forestPointsInLidar(scan), rig_.T_body_lidar, sweep, scan.t_end_s)
          .cloud_in_body;
  outcome.timing.deskew_ms = msSince(start);

  auto stage = Clock::now();
  const PointCloud source_cloud = preprocess::voxelFilter(cloud_in_body, config_.voxel_size_m);
  outcome.source_points = source_cloud.size();
  outcome.timing.filter_ms = msSince(stage);

  stage = Clock::now();
  outcome.T_world_body = predicted;
  outcome.lidar = LidarFactor::kFirstScan;
  if (!local_map_.empty()) {
    outcome.registration = registerToMap(source_cloud.positions, predicted);
    if (judge(outcome, predicted, /*check_jump=*/false)) {
      outcome.T_world_body = outcome.registration.T_target_source;
    }
  }
  outcome.timing.registration_ms = msSince(stage);

  const double dt = scan.t_end_s - last.t_s;
  constant_velocity_ = ConstantVelocity{
      scan.t_end_s, outcome.T_world_body,
      dt > 0.0 ? lie::Vector6((last.T_world_body.inverse() * outcome.T_world_body).Log() / dt)
               : lie::Vector6::Zero()};
  outcome.v_world = outcome.T_world_body.rotation() * constant_velocity_->twist_per_s.head<3>();

  stage = Clock::now();
  maybeAddKeyframe(outcome, cloud_in_body);
  outcome.timing.map_ms = msSince(stage);
  outcome.timing.total_ms = msSince(start);
  return outcome;
}

registration::RegistrationResult LidarInertialOdometry::registerToMap(
    const std::vector<Eigen::Vector3d>& source, const lie::SE3& guess_T_world_body) {
  registration::NdtConfig ndt;
  ndt.resolution_m = config_.ndt_resolution_m;
  ndt.search = config_.ndt_neighbours == "direct1" ? registration::NeighbourSearch::kDirect1
                                                   : registration::NeighbourSearch::kDirect7;
  local_map_.beginRegistration();
  registration::RegistrationResult result;
  if (config_.method == "gicp") {
    result = registration::alignGicp(registration::GicpCloud(source, {}), local_map_.gicpCloud(),
                                     guess_T_world_body, {});
  } else {
    // Coarse to fine: each pass starts from the previous one's pose.
    lie::SE3 guess = guess_T_world_body;
    int iterations = 0;
    for (const registration::NdtTarget* target : local_map_.ndtTargets()) {
      result = config_.method == "d2d" ? registration::alignD2dNdt(source, *target, guess, ndt)
                                       : registration::alignNdt(source, *target, guess, ndt);
      iterations += result.iterations;
      if (result.num_inliers == 0) break;
      guess = result.T_target_source;
    }
    result.iterations = iterations;
  }
  // Points farther than a few coarse NDT cells from the map are new ground, not misalignment.
  result.fitness_m2 = registration::fitnessScore(
      source, local_map_.kdTree(), result.T_target_source, 2.0 * config_.coarsestNdtResolutionM());
  return result;
}

std::optional<backend::PoseMeasurement> LidarInertialOdometry::judge(ScanOutcome& outcome,
                                                                     const lie::SE3& predicted,
                                                                     bool check_jump) const {
  const registration::RegistrationResult& r = outcome.registration;
  const lie::Vector6 jump = (predicted.inverse() * r.T_target_source).Log();
  const double jump_m = jump.head<3>().norm(), jump_deg = jump.tail<3>().norm() / kDegToRad;
  std::string rejected;
  if (r.iterations == 0 || r.num_inliers == 0 || !std::isfinite(r.hessian_condition)) {
    rejected = "registration failed: " + r.reason;
  } else if (!std::isfinite(r.fitness_m2) || r.fitness_m2 > config_.max_fitness_m2) {
    rejected = fmt::format("fitness {:.3f} m^2 above {:.3f}", r.fitness_m2, config_.max_fitness_m2);
  } else if (check_jump && (jump_m > config_.max_jump_m || jump_deg > config_.max_jump_deg)) {
    rejected = fmt::format("{:.3f} m / {:.2f} deg from the IMU prediction", jump_m, jump_deg);
  }
  if (!rejected.empty()) {
    outcome.lidar = LidarFactor::kRejected;
    outcome.lidar_note = rejected;
    return std::nullopt;
  }
  // Thesis Eq. 36 (OdometryConfig::lidarSigmas, docs/odometry.md), ten times wider when the
  // registration did not converge or is degenerate.
  double inflation = 1.0;
  outcome.lidar = LidarFactor::kUsed;
  if (!r.converged || r.hessian_condition > config_.degenerate_condition) {
    inflation = 10.0;
    outcome.lidar = LidarFactor::kInflated;
    outcome.lidar_note =
        !r.converged ? "registration hit its iteration limit"
                     : fmt::format("degenerate: Hessian condition {:.3g}", r.hessian_condition);
  }
  // Roll and pitch keep sigma_sm: gravity in the IMU factor observes them, and a tighter lidar
  // factor would hold on to a tilted local map. Heading has no such second source, so it gets its
  // own, tighter sigma (docs/odometry.md). The factor's rotation tangent is in the body frame:
  // Sigma_body = R^T Sigma_world R.
  const LidarSigmas sigma = config_.lidarSigmas(r.fitness_m2, inflation);
  const Eigen::Matrix3d R_world_body = r.T_target_source.rotation().matrix();
  const Eigen::Vector3d rotation_variances_world(sigma.tilt_rad * sigma.tilt_rad,
                                                 sigma.tilt_rad * sigma.tilt_rad,
                                                 sigma.heading_rad * sigma.heading_rad);
  lie::Matrix6 covariance = lie::Matrix6::Zero();
  covariance.topLeftCorner<3, 3>() =
      Eigen::Matrix3d::Identity() * sigma.translation_m * sigma.translation_m;
  covariance.bottomRightCorner<3, 3>() =
      R_world_body.transpose() * rotation_variances_world.asDiagonal() * R_world_body;
  return backend::PoseMeasurement{r.T_target_source, covariance};
}

void LidarInertialOdometry::collectForAlignment(const ScanOutcome& outcome,
                                                const imu::Preintegrator* increment) {
  // The lidar's own pose where registration worked: the alignment must not see the IMU's
  // (wrongly levelled) prediction; the fused pose otherwise.
  const bool lidar_pose =
      outcome.lidar == LidarFactor::kUsed || outcome.lidar == LidarFactor::kInflated;
  alignment_times_.push_back(outcome.t_s);
  alignment_poses_.push_back(lidar_pose ? outcome.registration.T_target_source
                                        : outcome.T_world_body);
  if (increment) alignment_increments_.push_back(*increment);
}

void LidarInertialOdometry::levelWorld(ScanOutcome& outcome) {
  const imu::GravityAlignment a =
      imu::alignGravity(alignment_poses_, alignment_increments_, config_.imu.gravity_mps2);
  alignment_times_.clear();
  alignment_poses_.clear();
  alignment_increments_.clear();
  // A free estimate of |g| far from gravity means the poses and the IMU disagree (bad
  // registrations, a wrong time offset): keep the IMU attitude rather than trust it.
  if (std::abs(a.estimated_magnitude_mps2 - config_.imu.gravity_mps2) >
      0.05 * config_.imu.gravity_mps2) {
    logger().warn(
        "gravity alignment over the first {:.1f} s found |g| = {:.2f} m/s^2; keeping the IMU's "
        "attitude",
        config_.gravity_alignment_s, a.estimated_magnitude_mps2);
    levelled_ = true;
    return;
  }
  const lie::SE3 T_new_old(a.R_levelled_world, Eigen::Vector3d::Zero());
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
  const double tilt_sigma = 0.3 * kDegToRad;
  levelled.covariance.diagonal().head<9>() << Eigen::Vector3d::Constant(1e-6),
      tilt_sigma * tilt_sigma, tilt_sigma * tilt_sigma, 1e-6,
      Eigen::Vector3d::Constant(0.05 * 0.05);
  smoother_.initialize(levelled);
  // The keyframes so far were deskewed with the velocity still unknown (zero at the start): the
  // local map starts over from this scan, deskewed with the velocity the odometry has found.
  local_map_.clear();
  last_keyframe_T_world_body_.reset();
  outcome.T_world_body = poseOf(levelled.state);
  outcome.v_world = levelled.state.v_world;
  for (StampedPose& p : outcome.imu_rate_poses) p.pose = T_new_old * p.pose;
  outcome.world_correction = T_new_old;
  levelled_ = true;
  const double tilt_deg =
      std::acos(std::clamp(a.gravity_world.normalized().z() * -1.0, -1.0, 1.0)) / kDegToRad;
  logger().info(
      "gravity alignment: the initial attitude was off by {:.2f} deg of tilt; world frame levelled "
      "(|g| estimated {:.3f} m/s^2)",
      tilt_deg, a.estimated_magnitude_mps2);
  initialization_note_ +=
      fmt::format("; levelled after {:.1f} s by {:.2f} deg", config_.gravity_alignment_s, tilt_deg);
}

void LidarInertialOdometry::maybeAddKeyframe(ScanOutcome& outcome,
                                             const PointCloud& cloud_in_body) {
  if (last_keyframe_T_world_body_) {
    const lie::Vector6 moved =
        (last_keyframe_T_world_body_->inverse() * outcome.T_world_body).Log();
    const double travelled_m =
        (outcome.T_world_body.translation() - last_keyframe_T_world_body_->translation()).norm() +
        config_.keyframe_rotation_weight_m_per_rad * moved.tail<3>().norm();
    if (travelled_m < config_.keyframe_distance_m) return;
  }
  outcome.keyframe = true;
  last_keyframe_T_world_body_ = outcome.T_world_body;
  local_map_.addKeyframe(
      outcome.t_s, outcome.T_world_body,
      preprocess::voxelFilter(cloud_in_body, config_.local_map_voxel_m).positions);
  outcome.keyframe_cloud_in_body = cloud_in_body;
}

}  // namespace taiga::pipeline
