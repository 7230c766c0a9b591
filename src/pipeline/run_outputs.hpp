#pragma once
// The files of `taiga run` (run.hpp) that observe the SLAM system as it goes: the trajectories
// and the per-scan logs; and the end-of-run files (loops.csv, summary.json). Internal to the
// pipeline.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <vector>

#include "taiga/core/trajectory.hpp"
#include "taiga/mapping/mapper.hpp"
#include "taiga/pipeline/run.hpp"
#include "taiga/pipeline/slam_system.hpp"

namespace taiga::pipeline {

/// The per-scan trajectories: the odometry's (T_odom_body, at scan and IMU rate) and the live
/// one as published (T_map_odom * T_odom_body); at the end, the odometry's corrected by the graph.
class TrajectoryRecorder final : public SlamObserver {
 public:
  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;
  void onKeyframe(std::uint64_t id, const ScanOutcome& scan) override;

  const Trajectory& odometry() const { return odometry_; }
  /// trajectory_odometry.tum (turned by R_level_odom, the odometry's final levelling),
  /// trajectory_online.tum (as published), trajectory.tum and trajectory_imu.tum (corrected by
  /// `graph`) into `dir`; returns trajectory.tum's T_map_body.
  Trajectory write(const std::filesystem::path& dir, const mapping::PoseGraph& graph,
                   const lie::SO3& R_level_odom) const;

 private:
  Trajectory odometry_, imu_rate_, online_;
  std::vector<double> keyframe_times_s_;
};

/// timing.csv and scans.csv, a row per scan as it is published, and the counts and per-scan
/// times of summary.json.
class ScanLog final : public SlamObserver {
 public:
  explicit ScanLog(const std::filesystem::path& dir);

  /// The reader's time to read and decode the events up to scan `scan_index` since the previous
  /// scan, for that scan's row.
  void chargeReadTime(std::uint64_t scan_index, double read_ms);
  /// A scan read without per-point times, which the reader made up (io/point_fields.hpp).
  void countMadeUpTimes() { ++made_up_times_; }
  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;
  void onKeyframe(std::uint64_t id, const ScanOutcome& scan) override;
  void onLocalMapRebuilt() override { ++local_map_rebuilds_; }
  void onImu(const ImuSample&) override { ++imu_samples_; }

  /// scans_processed, imu_samples, keyframes, the lidar factor counts, local_map_rebuilds and
  /// the per-scan time statistics.
  void fillSummary(RunSummary& summary) const;

 private:
  std::ofstream timing_, scans_;
  std::map<std::uint64_t, double> read_ms_;  ///< by scan index, until its row is written
  std::vector<double> totals_ms_;
  std::size_t imu_samples_ = 0, keyframes_ = 0, rejected_ = 0, inflated_ = 0;
  std::size_t local_map_rebuilds_ = 0, made_up_times_ = 0;
};

std::ofstream openOutput(const std::filesystem::path& path);

/// loops.csv: every loop closure attempt, accepted or not, and why.
void writeLoops(const std::filesystem::path& path,
                const std::vector<mapping::LoopRecord>& attempts);

/// clock_offset.csv: every re-estimate of the lidar-IMU time offset (clock_tracker.hpp).
void writeClockWindows(const std::filesystem::path& path, const std::vector<ClockWindow>& windows);

/// summary.json.
void writeSummary(const std::filesystem::path& path, const RunSummary& summary,
                  const std::filesystem::path& recording,
                  const std::optional<mapping::GnssFusionReport>& gnss_fusion);

}  // namespace taiga::pipeline
