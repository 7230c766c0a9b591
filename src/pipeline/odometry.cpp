#include "taiga/pipeline/odometry.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "health_monitor.hpp"
#include "lidar_factor.hpp"
#include "motion_prior.hpp"
#include "scan_preparation.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/log.hpp"
#include "taiga/preprocess/voxel_filter.hpp"
#include "taiga/registration/kdtree.hpp"
#include "wide_basin.hpp"

namespace taiga::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

/// A scan within this share of the keyframe spacing from the last keyframe is registered from
/// that keyframe's own viewpoint (HealthEvidence::at_keyframe_viewpoint): a quarter, so that a
/// rig moving at any pace still feeds the health monitor's yardstick with most of its scans.
constexpr double kKeyframeViewpointShare = 0.25;

/// The fitness is a mean over the scan's points; its nearest-neighbour searches cost as much as
/// the NDT passes, so a dense scan (a full OS0-128 scan leaves 16000 voxels) is scored on every
/// k-th point, about 4000 of them. On the demo that moved the fitness by 0.2 % in the median
/// and 11 % at the 95th percentile, against a factor of 10 between a typical fitness (0.03 m^2)
/// and the lidar factor's threshold (0.3 m^2): the trajectory stayed byte for byte the same
/// (bench/BENCHMARK.md, "Session 37"). Sparser scans keep every point.
std::vector<Eigen::Vector3d> fitnessSample(const std::vector<Eigen::Vector3d>& source) {
  constexpr std::size_t kFitnessPoints = 4000;
  const std::size_t stride = std::max<std::size_t>(1, source.size() / kFitnessPoints);
  if (stride == 1) return source;
  std::vector<Eigen::Vector3d> sample;
  sample.reserve(source.size() / stride + 1);
  for (std::size_t i = 0; i < source.size(); i += stride) sample.push_back(source[i]);
  return sample;
}

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// The local map's NDT passes, coarse to fine. The IMU predicts within centimetres: the fine
/// cells' basin suffices. The constant-velocity prediction of lidar-only odometry may be off by
/// decimetres: coarse to fine.
std::vector<double> localMapResolutionsM(const OdometryConfig& config, bool lidar_only) {
  if (lidar_only) return config.ndtResolutionsM();
  return {config.ndt_resolution_m};
}

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

const char* scanStatusName(ScanStatus status) {
  switch (status) {
    case ScanStatus::kOk:
      return "ok";
    case ScanStatus::kDegraded:
      return "degraded";
    case ScanStatus::kLost:
      return "lost";
  }
  return "?";
}

Odometry::Odometry(const OdometryConfig& config, const RigConfig& rig, bool lidar_only)
    : config_(config),
      lidar_only_(lidar_only),
      registration_(registration::registrationConfigFor(config)),
      preparation_(std::make_unique<ScanPreparation>(config, rig)),
      motion_(makeMotionPrior(lidar_only, config, rig, *preparation_, registration_)),
      local_map_(localMapResolutionsM(config, lidar_only), config.local_map_voxel_m,
                 config.local_map_keyframes,
                 registration_.method == registration::Method::kGicp ? LocalMap::Target::kGicp
                                                                     : LocalMap::Target::kNdt,
                 registration_.gicp, registration_.ndt, rig.T_body_lidar.translation()),
      health_(std::make_unique<HealthMonitor>(config.health, config.max_fitness_m2)),
      wide_basin_(std::make_unique<WideBasin>(config)) {}

Odometry::~Odometry() = default;

void Odometry::addImu(const ImuSample& sample) { motion_->addImu(sample); }

void Odometry::setMovingBoxes(MovingBoxes boxes_body) {
  preparation_->setMovingBoxes(std::move(boxes_body));
}

bool Odometry::odomFrameFinal() const { return motion_->levelled(); }

const std::string& Odometry::initializationNote() const { return motion_->initializationNote(); }

lie::SO3 Odometry::R_level_odom() const { return motion_->R_level_odom(); }

std::vector<ScanOutcome> Odometry::addScan(const io::Scan& scan) {
  std::vector<ScanOutcome> outcomes;
  std::optional<FirstScan> first;
  if (!motion_->start(scan, first)) return outcomes;
  if (first) outcomes.push_back(firstScanOutcome(std::move(*first)));
  if (std::optional<ScanOutcome> outcome = processScan(scan))
    outcomes.push_back(std::move(*outcome));
  return outcomes;
}

ScanOutcome Odometry::firstScanOutcome(FirstScan&& first) {
  ScanOutcome outcome;
  outcome.scan_index = first.index;
  outcome.t_s = first.t_s;
  outcome.T_odom_body = first.state.T_odom_body;
  outcome.v_odom = first.state.v_odom;
  outcome.bias = first.state.bias;
  outcome.lidar = LidarFactor::kFirstScan;
  judgeHealth(outcome, false);
  maybeAddKeyframe(outcome, std::move(first.cloud_in_body));
  return outcome;
}

std::optional<ScanOutcome> Odometry::processScan(const io::Scan& scan) {
  const auto start = Clock::now();
  if (const std::optional<double> t_state_s = motion_->stateTime();
      t_state_s && scan.t_end_s <= *t_state_s) {
    logger().warn("scan {} ends at {:.6f} s, not after the previous state at {:.6f} s; skipped",
                  scan.index, scan.t_end_s, *t_state_s);
    return std::nullopt;
  }
  ScanOutcome outcome;
  outcome.scan_index = scan.index;
  outcome.t_s = scan.t_end_s;

  // 1. Predict; 2. deskew into the body frame at the scan's end.
  MotionPrediction prediction = motion_->predict(scan);
  outcome.imu_rate_poses = std::move(prediction.imu_rate_poses);
  outcome.imu_gap_s = prediction.imu_gap_s;
  PointCloud cloud_in_body = preparation_->deskewedInBody(scan, prediction.sweep_T_odom_body);
  outcome.timing.deskew_ms = msSince(start);

  // 3. Voxel filter.
  auto stage = Clock::now();
  outcome.source_cloud_in_body = std::make_shared<const PointCloud>(preprocess::voxelFilter(
      cloud_in_body, config_.voxel_size_m, preprocess::voxelRepresentative(config_.voxel_point)));
  const PointCloud& source_cloud = *outcome.source_cloud_in_body;
  outcome.source_points = source_cloud.size();
  outcome.timing.filter_ms = msSince(stage);

  // 4. Register to the local map (none before the first keyframe without an IMU).
  stage = Clock::now();
  const bool has_map = !local_map_.empty();
  if (has_map) {
    outcome.registration =
        registerToMap({source_cloud.positions, cloud_in_body.positions}, prediction, scan.t_end_s);
    const lie::Vector6 innovation =
        (prediction.T_odom_body.inverse() * outcome.registration.T_target_source).Log();
    outcome.innovation_m = innovation.head<3>().norm();
    outcome.innovation_deg = innovation.tail<3>().norm() * kDegPerRad;
  }
  outcome.timing.registration_ms = msSince(stage);

  // 5. Judge it; 6. fuse it with the motion prior.
  stage = Clock::now();
  LidarFactorVerdict verdict{.factor = LidarFactor::kFirstScan};
  if (has_map) {
    std::optional<JumpBound> jump_bound = motion_->jumpBound();
    if (jump_bound)
      *jump_bound = grownByDeadReckoning(*jump_bound, health_->sinceOk_s(scan.t_end_s));
    verdict = judgeRegistration(outcome.registration, prediction.T_odom_body, jump_bound, config_);
  }
  outcome.lidar = verdict.factor;
  outcome.lidar_note = verdict.note;
  const MotionUpdate update = motion_->update(verdict.measurement);
  outcome.T_odom_body = update.state.T_odom_body;
  outcome.v_odom = update.state.v_odom;
  outcome.bias = update.state.bias;
  outcome.covariance = update.state.covariance;
  if (update.T_odom_unlevelled) {
    // The keyframes so far were deskewed with the velocity still unknown (zero at the start): the
    // local map starts over from this scan, deskewed with the velocity the odometry has found.
    local_map_.clear();
    last_keyframe_T_odom_body_.reset();
    health_->forgetHistory();
    wide_basin_->forget();
    for (StampedPose& p : outcome.imu_rate_poses) p.pose = *update.T_odom_unlevelled * p.pose;
    outcome.T_odom_unlevelled = update.T_odom_unlevelled;
  }
  outcome.timing.optimization_ms = msSince(stage);

  // 7. Health, then the keyframe test.
  stage = Clock::now();
  judgeHealth(outcome, has_map);
  // With an IMU the wide basin is rare and keeps no yardstick: every such scan is searched.
  if (lidar_only_ && has_map && outcome.health.status == ScanStatus::kOk)
    wide_basin_->rememberLast();
  maybeAddKeyframe(outcome, std::move(cloud_in_body));
  outcome.timing.map_ms = msSince(stage);
  outcome.timing.total_ms = msSince(start);
  return outcome;
}

registration::RegistrationResult Odometry::registerToMap(const RegistrationSource& source,
                                                         const MotionPrediction& prediction,
                                                         double t_s) {
  local_map_.beginRegistration();
  const lie::SE3& guess_T_odom_body = prediction.T_odom_body;
  const std::vector<const registration::NdtTarget*> passes =
      registration_.method == registration::Method::kGicp
          ? std::vector<const registration::NdtTarget*>{}
          : ndtPasses(prediction.constant_velocity);
  registration::RegistrationResult result = alignToMap(source, guess_T_odom_body, passes);
  // The IMU predicts within centimetres, unless it has dead-reckoned for long without an ok scan
  // (no scans, or none trusted): after 4 s the prediction was 0.7 m off, and NDT's 0.5 m cells
  // settled 0.4 m from the truth, a scan the monitor still called ok.
  if (!lidar_only_ && health_->sinceOk_s(t_s) < kImuBlindBeforeWideBasin_s) return result;
  return wide_basin_->widen(
      source.points, guess_T_odom_body, std::move(result), local_map_, *health_,
      [&](const lie::SE3& guess) { return alignToMap(source, guess, passes); });
}

std::vector<const registration::NdtTarget*> Odometry::ndtPasses(bool constant_velocity) const {
  std::vector<const registration::NdtTarget*> passes = local_map_.ndtTargets();
  // Across a 1 s gap in a handheld's IMU readings, the twist of the last states predicted the
  // sway degrees off; the 0.5 m cells alone then settled ever farther off, lost the track and
  // diverged by tens of metres on 2 of 8 `harsh` seeds (docs/odometry.md, Health).
  const double coarse_m = config_.coarsestNdtResolutionM();
  if (constant_velocity && passes.size() == 1 && coarse_m > passes.front()->resolution_m())
    passes.insert(passes.begin(), &local_map_.coarseNdtTarget(coarse_m));
  return passes;
}

registration::RegistrationResult Odometry::alignToMap(
    const RegistrationSource& source, const lie::SE3& guess_T_odom_body,
    const std::vector<const registration::NdtTarget*>& ndt_passes) const {
  registration::RegistrationResult result;
  if (registration_.method == registration::Method::kGicp) {
    result = registration::alignGicp(registration::GicpCloud(source.points, {}),
                                     local_map_.gicpCloud(), guess_T_odom_body, registration_.gicp);
  } else {
    // Coarse to fine: each pass starts from the previous one's pose.
    lie::SE3 guess = guess_T_odom_body;
    int iterations = 0;
    for (const registration::NdtTarget* target : ndt_passes) {
      result = registration_.method == registration::Method::kD2dNdt
                   ? registration::alignD2dNdt(source.unfiltered, *target, guess, registration_.ndt)
                   : registration::alignNdt(source.points, *target, guess, registration_.ndt);
      iterations += result.iterations;
      if (result.num_inliers == 0) break;
      guess = result.T_target_source;
    }
    result.iterations = iterations;
  }
  // Points farther than a few coarse NDT cells from the map are new ground, not misalignment.
  result.fitness_m2 =
      registration::agreement(fitnessSample(source.points), local_map_.nearest(),
                              result.T_target_source, 2.0 * config_.coarsestNdtResolutionM())
          .fitness_m2;
  return result;
}

void Odometry::judgeHealth(ScanOutcome& outcome, bool registered) {
  const registration::RegistrationResult& r = outcome.registration;
  outcome.health = health_->judge(
      {.t_s = outcome.t_s,
       .registered = registered,
       .lidar = outcome.lidar,
       .lidar_note = outcome.lidar_note,
       .fitness_m2 = r.fitness_m2,
       .inlier_share = inlierShare(r, outcome.source_points),
       .v_odom = outcome.v_odom,
       .bias = outcome.bias,
       .estimates_bias = !lidar_only_,
       .frame_levelled = motion_->levelled(),
       .imu_gap_s = outcome.imu_gap_s,
       .at_keyframe_viewpoint = fromLastKeyframe_m(outcome.T_odom_body) <
                                kKeyframeViewpointShare * config_.keyframe_distance_m});
  if (health_->restartLocalMap()) {
    // Lost for long: the old local map no longer explains the scans. A new segment starts with
    // this scan, placed by dead reckoning (docs/odometry.md, "Health").
    local_map_.clear();
    last_keyframe_T_odom_body_.reset();
    health_->localMapRestarted(outcome.t_s);
    wide_basin_->forget();
    ++map_segment_;
    // The state the loss left is not trusted either: with an IMU the motion model starts again
    // from the next two scans, and the new map from the first of them, not from this scan, which
    // was deskewed with that state. Started from it, a 2 s gap in the IMU readings left 4 m/s and
    // 12 deg of tilt in the new segment, which diverged by 70 m (docs/odometry.md, Health).
    motion_restarted_ = motion_->restart(outcome.T_odom_body);
    logger().warn("scan {} at {:.3f} s: lost for long, the local map starts over (segment {}{})",
                  outcome.scan_index, outcome.t_s, map_segment_,
                  motion_restarted_ ? ", the odometry from the next two scans" : "");
  }
  outcome.map_segment = map_segment_;
}

double Odometry::fromLastKeyframe_m(const lie::SE3& T_odom_body) const {
  if (!last_keyframe_T_odom_body_) return std::numeric_limits<double>::infinity();
  const lie::Vector6 moved = (last_keyframe_T_odom_body_->inverse() * T_odom_body).Log();
  return (T_odom_body.translation() - last_keyframe_T_odom_body_->translation()).norm() +
         config_.keyframe_rotation_weight_m_per_rad * moved.tail<3>().norm();
}

void Odometry::maybeAddKeyframe(ScanOutcome& outcome, PointCloud&& cloud_in_body) {
  // A scan the monitor distrusts never enters the map, but an empty map takes the next scan
  // whatever its status: there is nothing else to register to.
  if (outcome.health.status != ScanStatus::kOk && !local_map_.empty()) return;
  if (std::exchange(motion_restarted_, false)) return;  // the restart's first scan starts the map
  if (fromLastKeyframe_m(outcome.T_odom_body) < config_.keyframe_distance_m) return;
  outcome.keyframe_id = keyframes_made_++;
  last_keyframe_T_odom_body_ = outcome.T_odom_body;
  local_map_.addKeyframe(*outcome.keyframe_id, outcome.T_odom_body,
                         preparation_->localMapPoints(cloud_in_body));
  outcome.keyframe_cloud_in_body = std::move(cloud_in_body);
}

}  // namespace taiga::pipeline
