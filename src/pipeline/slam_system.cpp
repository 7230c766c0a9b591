#include "taiga/pipeline/slam_system.hpp"

#include <chrono>
#include <stdexcept>
#include <utility>

#include "motion_prior.hpp"
#include "odometry_correction.hpp"

namespace taiga::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

mapping::MappingThreadOptions mappingThreadOptions(const SystemConfig& config,
                                                   const SlamOptions& options,
                                                   const mapping::KeyframeStore& store,
                                                   const std::vector<SlamObserver*>& observers) {
  mapping::MappingThreadOptions out;
  out.gnss = config.georef;
  // The snapshots the odometry follows (step 11), as many as its local map holds.
  if (config.mapping.correct_odometry)
    out.snapshot_keyframes = static_cast<std::size_t>(config.odometry.local_map_keyframes);
  out.after_keyframe = [&store, &observers,
                        write_poses = options.live_keyframe_poses](const mapping::Mapper& mapper) {
    if (write_poses) store.writePoses(mapper.keyframeTrajectory());
    for (SlamObserver* observer : observers) observer->onGraph(mapper);
  };
  return out;
}

/// An outcome held before the odom frame was levelled, in the levelled frame.
void reexpress(ScanOutcome& outcome, const lie::SE3& T_odom_unlevelled) {
  outcome.T_odom_body = T_odom_unlevelled * outcome.T_odom_body;
  for (StampedPose& p : outcome.imu_rate_poses) p.pose = T_odom_unlevelled * p.pose;
  if (outcome.covariance)
    outcome.covariance = rotatedCovariance(*outcome.covariance, T_odom_unlevelled.rotation());
}

}  // namespace

SlamSystem::SlamSystem(const SystemConfig& config, SlamOptions options)
    : mapping_config_(config.mapping),
      odometry_(config.odometry, config.rig, options.lidar_only),
      // Keyframe scans go to disk in the body frame as they are made (memory stays flat); only
      // the registration-resolution copy that loop closure registers stays in RAM.
      store_(mapping::KeyframeStore::create(
          options.keyframe_dir, {.registration_voxel_m = config.odometry.voxel_size_m,
                                 .registration_voxel_point = preprocess::voxelRepresentative(
                                     config.odometry.voxel_point)})),
      mapping_thread_(config.mapping, config.odometry, store_,
                      mappingThreadOptions(config, options, store_, observers_)),
      correction_(std::make_unique<OdometryCorrection>(
          static_cast<std::size_t>(config.odometry.local_map_keyframes))) {
  odometry_.setMovingBoxes(std::move(options.moving_boxes_body));
}

SlamSystem::~SlamSystem() = default;

void SlamSystem::add(const io::RecordingEvent& event) {
  std::visit([this](const auto& e) { add(e); }, event);
}

void SlamSystem::add(const ImuSample& sample) {
  odometry_.addImu(sample);
  for (SlamObserver* observer : observers_) observer->onImu(sample);
}

void SlamSystem::add(const io::Scan& scan) {
  // Steps 1-7; a scan may complete none (the IMU is still initializing) or two (the first scan's
  // state needs the second).
  for (ScanOutcome& outcome : odometry_.addScan(scan)) publish(std::move(outcome));
}

void SlamSystem::add(const GnssFix& fix) { publish(fix); }

void SlamSystem::publish(Event event) {
  if (!odometry_.odomFrameFinal()) {
    held_.push_back(std::move(event));
    return;
  }
  if (auto* outcome = std::get_if<ScanOutcome>(&event)) {
    releaseHeld(outcome->T_odom_unlevelled);
    handleOutcome(*outcome, /*live=*/true);
  } else {
    releaseHeld(std::nullopt);
    handleFix(std::get<GnssFix>(event));
  }
}

void SlamSystem::releaseHeld(const std::optional<lie::SE3>& T_odom_unlevelled) {
  for (Event& event : held_) {
    if (auto* outcome = std::get_if<ScanOutcome>(&event)) {
      if (T_odom_unlevelled) reexpress(*outcome, *T_odom_unlevelled);
      handleOutcome(*outcome, /*live=*/false);
    } else {
      handleFix(std::get<GnssFix>(event));
    }
  }
  held_.clear();
}

void SlamSystem::handleOutcome(const ScanOutcome& outcome, bool live) {
  // 8. Publish the pose, with the graph's correction as the live system has it.
  for (SlamObserver* observer : observers_) observer->onScan(outcome, correction_->T_map_odom());
  if (!outcome.keyframe_id) return;
  // 9. The keyframe's scan to disk; 10. into the mapping graph.
  // The odometry's source cloud is the scan filtered as the store's registration copies are
  // (both at odometry.voxel_size_m with its voxel_point): the store keeps it, not a refiltering.
  const std::uint64_t id =
      store_.add(outcome.t_s, outcome.T_odom_body, *outcome.keyframe_cloud_in_body,
                 outcome.source_cloud_in_body ? &outcome.source_cloud_in_body->positions : nullptr);
  if (id != *outcome.keyframe_id)
    throw std::logic_error("SlamSystem: the store's keyframe ids differ from the odometry's");
  mapping_thread_.addKeyframe(id, outcome.t_s, outcome.T_odom_body, outcome.map_segment);
  correction_->addKeyframe(id, outcome.T_odom_body);
  for (SlamObserver* observer : observers_) observer->onKeyframe(id, outcome);
  // 11. Follow the graph. Keyframes released after levelling predate the local map, which
  // started over at levelling: nothing to follow for them.
  if (live && mapping_config_.correct_odometry && id >= OdometryCorrection::kDelayKeyframes)
    followGraph(id - OdometryCorrection::kDelayKeyframes);
}

void SlamSystem::handleFix(const GnssFix& fix) {
  if (mapping_config_.gnss_fusion) mapping_thread_.addGnssFix(fix);
  for (SlamObserver* observer : observers_) observer->onGnssFix(fix);
}

void SlamSystem::followGraph(std::uint64_t id) {
  // Waits if the mapping thread is behind, so the correction depends on the data, not on timing.
  const auto wait_start = Clock::now();
  const std::optional<mapping::GraphSnapshot> snapshot = mapping_thread_.waitForSnapshot(id);
  correction_wait_s_ += std::chrono::duration<double>(Clock::now() - wait_start).count();
  if (snapshot && correction_->apply(*snapshot, !odometry_.lidarOnly(), odometry_))
    for (SlamObserver* observer : observers_) observer->onLocalMapRebuilt();
}

const mapping::Mapper& SlamSystem::finish() {
  if (!finished_) {
    releaseHeld(std::nullopt);  // a run too short to level: its frame is the unlevelled one
    finished_ = true;
  }
  const mapping::Mapper& mapper = mapping_thread_.finish(odometry_.R_level_odom());
  store_.setPoses(mapper.graph().poses());
  store_.writePoses();
  return mapper;
}

}  // namespace taiga::pipeline
