#pragma once
// The whole SLAM system of the thesis' Figure 2 ("Robotics Approach in Mobile Laser Scanning",
// 3.1) as one object that takes one event at a time (IMU reading, scan, GNSS fix) and tells its
// observers what happened. Per scan:
//   1-7. the odometry (odometry.hpp): predict, deskew, filter, register to the local map, judge,
//        fuse, keyframe test; poses T_odom_body in the continuous odom frame
//   8.   publish the scan's outcome, with the map->odom correction the live pose is published with
//   9.   a keyframe's full scan to the keyframe store on disk (the map is exported from there)
//   10.  the keyframe into the mapping graph (mapping/mapper.hpp), which searches and verifies
//        loop closures on its own thread; GNSS fixes join it with mapping.gnss_fusion
//   11.  the odometry follows the graph's corrections two keyframes late (odometry_correction.hpp)
// Frames (docs/frames.md): the odometry's poses are T_odom_*, the graph's T_map_*. Nothing leaves
// the system in the odometry's unlevelled start frame: outcomes and fixes are held until the
// gravity alignment has levelled the odom frame, then published re-expressed, in their order.
//
// The system writes no file but the keyframe store; trajectories, logs, the summary and the
// georeference are observers (run_outputs.hpp), so a live front end can reuse the same core.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <variant>
#include <vector>

#include "taiga/core/box.hpp"
#include "taiga/core/sensor_samples.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/mapper.hpp"
#include "taiga/pipeline/odometry.hpp"

namespace taiga::pipeline {

class OdometryCorrection;

/// Receives what the system does, on the caller's thread, in the order it happens.
class SlamObserver {
 public:
  virtual ~SlamObserver() = default;
  /// A scan's outcome (T_odom_body) and the correction T_map_odom that the live pose
  /// T_map_odom * T_odom_body is published with.
  virtual void onScan(const ScanOutcome& /*scan*/, const lie::SE3& /*T_map_odom*/) {}
  /// The scan just published became keyframe `id` of the store.
  virtual void onKeyframe(std::uint64_t /*id*/, const ScanOutcome& /*scan*/) {}
  /// The odometry rebuilt its local map in the shape the graph gave it.
  virtual void onLocalMapRebuilt() {}
  /// The mapping graph after it handled a keyframe (its keyframe poses, loop closures). Called
  /// on the mapping thread, not the main thread: an observer that shares state must lock.
  virtual void onGraph(const mapping::Mapper& /*mapper*/) {}
  virtual void onGnssFix(const GnssFix& /*fix*/) {}
  virtual void onImu(const ImuSample& /*sample*/) {}
};

struct SlamOptions {
  std::filesystem::path keyframe_dir;  ///< the keyframe store (created)
  bool lidar_only = false;             ///< no IMU: constant-velocity motion prior
  MovingBoxes moving_boxes_body;       ///< per-scan boxes around moving parts of the rig
  /// Rewrite keyframe_dir/poses.tum with the graph's poses after every keyframe, so that
  /// `taiga export-map` can export the map of a run still going.
  bool live_keyframe_poses = true;
};

class SlamSystem {
 public:
  SlamSystem(const SystemConfig& config, SlamOptions options);
  ~SlamSystem();
  SlamSystem(const SlamSystem&) = delete;
  SlamSystem& operator=(const SlamSystem&) = delete;

  /// Observers are told in the order they were added; they must be added before the first input
  /// (the mapping thread reads the list) and outlive it.
  void addObserver(SlamObserver& observer) { observers_.push_back(&observer); }
  void add(const io::RecordingEvent& event);
  void add(const ImuSample& sample);
  void add(const io::Scan& scan);
  void add(const GnssFix& fix);
  /// End of the input: publishes what is still held, waits for the mapping graph's last loop
  /// closures and gives the keyframe store the graph's final poses (written to poses.tum). Once.
  const mapping::Mapper& finish();

  const Odometry& odometry() const { return odometry_; }
  const mapping::KeyframeStore& keyframes() const { return store_; }
  /// Wall time the odometry waited for the mapping thread's snapshots, s.
  double correctionWait_s() const { return correction_wait_s_; }

 private:
  using Event = std::variant<ScanOutcome, GnssFix>;
  /// Publishes an event, or holds it while the odom frame is not final.
  void publish(Event event);
  /// Publishes the held events, re-expressed in the levelled frame when it changed.
  void releaseHeld(const std::optional<lie::SE3>& T_odom_unlevelled);
  /// Steps 8-11 for one outcome; `live`: published as it happened, not released after levelling.
  void handleOutcome(const ScanOutcome& outcome, bool live);
  void handleFix(const GnssFix& fix);
  /// Step 11: the graph as it was after keyframe `id`.
  void followGraph(std::uint64_t id);

  MappingConfig mapping_config_;
  std::vector<SlamObserver*> observers_;
  Odometry odometry_;
  mapping::KeyframeStore store_;
  mapping::MappingThread mapping_thread_;
  std::unique_ptr<OdometryCorrection> correction_;
  std::vector<Event> held_;  ///< published once the odom frame is final
  double correction_wait_s_ = 0.0;
  bool finished_ = false;
};

}  // namespace taiga::pipeline
