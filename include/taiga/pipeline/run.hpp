#pragma once
// `taiga run`: the SLAM system (slam_system.hpp) over a whole recording, and its outputs (frames
// in docs/frames.md):
//   trajectory.tum       one pose per scan (T_map_body at the scan's end): the odometry
//                        corrected by the mapping graph (loop closures)
//   trajectory_imu.tum   IMU-rate poses (propagated between scans), corrected likewise
//   trajectory_odometry.tum  the odometry's per-scan poses T_odom_body, uncorrected
//   trajectory_online.tum    the per-scan poses as published live, T_map_odom * T_odom_body:
//                        with mapping.correct_odometry the graph's corrections as they come
//   keyframes.tum        the keyframe poses optimized by the mapping graph
//   loops.csv            every loop closure attempt: candidate, fitness, correction, verdict
//   keyframes/           every keyframe's full deskewed scan in the body frame (NNNNNN.tkf,
//                        mapping/keyframe_file.hpp), written as keyframes are made so memory
//                        stays flat, and their final poses (poses.tum): `taiga export-map`
//                        re-exports the map from it
//   map.las              every keyframe's scan in the map frame with its final pose (GPS
//                        time = point time, point source ID = keyframe number), exported from
//                        keyframes/ at the end of the run (mapping/map_export.hpp); map.ply on
//                        request
//   timing.csv           per scan: t_s and the stage durations in ms (docs/formats.md)
//   scans.csv            per scan: registration diagnostics (fitness, iterations, lidar factor)
//   summary.json         counts, per-scan time statistics, real-time factor, peak memory
//   georef/              with GNSS fixes in the recording: trajectory.tum fitted to them
//                        (config georef:), in the projected CRS: trajectory_epsgNNNN.csv,
//                        trajectory.geojson, georef.yaml and map_epsgNNNN.las (run_georef.hpp)

#include <Eigen/Core>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "taiga/core/system_config.hpp"
#include "taiga/io/ouster/live.hpp"
#include "taiga/pipeline/clock_tracker.hpp"
#include "taiga/pipeline/sweep_check.hpp"

namespace taiga::pipeline {

struct RunOptions {
  std::filesystem::path out_dir;
  bool write_ply = false;  ///< also map.ply (holds the map in memory while it is written)
  /// > 0: the map is decimated to one point per voxel across all keyframes (the point nearest
  /// each voxel's centre, mapping/map_export.hpp)
  double map_voxel_m = 0.0;
  bool realtime = false;                 ///< replay at sensor rate, dropping scans when behind
  std::size_t realtime_queue_scans = 2;  ///< scans that may wait before the oldest is dropped
  bool show_progress = true;             ///< a progress line on a terminal
  /// Per-scan boxes around moving parts of the rig (io/moving_boxes.hpp); empty: none.
  std::filesystem::path moving_boxes_file;
  /// "host:port": the web viewer (docs/viewer.md) served there, with the Foxglove channels on
  /// the same port (instead of live.foxglove); empty: no viewer.
  std::string view;
};

/// What a live run would have seen (--realtime): scans dropped because the odometry was behind,
/// and the latency from a scan's delivery to its pose.
struct RealtimeReport {
  std::size_t dropped_scans = 0;
  double latency_p50_ms = 0.0, latency_p95_ms = 0.0, latency_p99_ms = 0.0, latency_max_ms = 0.0;
};

/// The georeferencing at the end of a run whose recording has GNSS fixes.
struct GeorefRunReport {
  std::size_t fixes = 0;  ///< GNSS fixes in the recording
  std::string skipped;    ///< why the run is not georeferenced; empty when it is
  std::string method;
  int epsg = 0;
  std::size_t inliers = 0, outliers = 0;
  double horizontal_rms_m = 0.0, vertical_rms_m = 0.0;
  /// 1-sigma of the fit: east, north, up (m), roll, pitch, yaw (rad).
  Eigen::Matrix<double, 6, 1> sigma = Eigen::Matrix<double, 6, 1>::Zero();
  double map_export_s = 0.0;  ///< georef/map_epsgNNNN.las
};

/// Consecutive scans with the same status other than ok.
struct HealthStretch {
  std::string status;  ///< degraded or lost
  double from_s = 0.0, to_s = 0.0;
  std::size_t scans = 0;
  std::string reason;  ///< the first scan's
};

/// A map segment the mapping graph found in the map and tied to it (mapping/relocalization.hpp).
struct Reattachment {
  std::uint64_t segment = 0;
  double t_s = 0.0;                                 ///< of the keyframe that was found
  double correction_m = 0.0, correction_deg = 0.0;  ///< from where dead reckoning had put it
  double overlap = 0.0;                             ///< share of the keyframe's points on the map
};

/// What the odometry's health monitor said over the run (docs/odometry.md, "Health").
struct HealthReport {
  std::size_t ok = 0, degraded = 0, lost = 0;
  /// Local map segments: 1, plus one each time a lost local map was given up.
  std::size_t map_segments = 1;
  std::vector<HealthStretch> stretches;  ///< in time order
  bool ended_lost = false;
  /// With an IMU: the median over the used lidar factors of how far the registration moved the
  /// body from the IMU's prediction, and whether that exceeds
  /// odometry.health.max_median_innovation_deg (a wrong extrinsic rotation or time offset, or
  /// IMU noise settings far from the truth). NaN without an IMU.
  double median_innovation_deg = std::numeric_limits<double>::quiet_NaN();
  double median_innovation_m = std::numeric_limits<double>::quiet_NaN();
  bool calibration_suspect = false;
  /// Stretches of scans with fewer points after the voxel filter than
  /// odometry.health.sparse_scan_ratio of the run's median (status "sparse"): lost packets, a
  /// blocked view. A note on the run; the scans' statuses are the monitor's.
  std::vector<HealthStretch> sparse;
  std::size_t sparse_scans = 0;
  std::vector<Reattachment> reattached;  ///< segments after the first that were found again
  /// Lost and not re-attached to the same map: the run ended lost, or started a segment that
  /// was not re-attached.
  bool trackLost() const { return ended_lost || !floatingSegments().empty(); }
  /// The segments after the first that were never found in the map, in order.
  std::vector<std::uint64_t> floatingSegments() const;
  /// "ok", "degraded", "recovered" (lost, then re-attached to the same map), "suspect" (the
  /// calibration, see calibration_suspect) or "lost".
  std::string verdict() const;
};

/// The self-calibration before the run (calibration.at_start, docs/calibration.md).
struct CalibrationRunReport {
  std::string skipped;  ///< why the run kept the configured rig; empty when it calibrated
  double wall_time_s = 0.0;
  std::size_t passes = 0;
  double time_offset_s = 0.0;    ///< rig.lidar_time_offset_s the run used
  double offset_change_s = 0.0;  ///< from the configured one
  double offset_sigma_s = 0.0;
  bool offset_observable = false;
  double rotation_change_deg = 0.0;  ///< of R_body_lidar, from the configured one
  Eigen::Vector3d rotation_sigma_deg = Eigen::Vector3d::Zero();  ///< about body x, y, z
  std::string rotation_observable_axes;                          ///< e.g. "xyz", "xy", "" (none)
  std::string advice;  ///< what motion would calibrate what was not observable
  /// The gyro's noise density measured against the registrations (calib/gyro_noise.hpp) and the
  /// verdict on odometry.imu.gyro_noise_density; an understated one is replaced by the suggestion
  /// when calibration.apply_gyro_noise (docs/calibration.md).
  std::string gyro_noise_verdict = "undetermined";
  std::string gyro_noise_text;
  double gyro_noise_measured = 0.0, gyro_noise_sigma = 0.0;  ///< rad/s/sqrt(Hz); 0: not measured
  double gyro_noise_suggested = 0.0;                         ///< 0 when consistent
  bool gyro_noise_applied = false;  ///< the run used gyro_noise_suggested
  /// The lever arm's estimated change (body x, y, z) and its 1-sigma; the axes along which the
  /// run applied it (calibration.apply_lever_arm), e.g. "xz", "" (none). Zero: not estimated.
  Eigen::Vector3d lever_arm_change_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d lever_arm_sigma_m = Eigen::Vector3d::Zero();
  std::string lever_arm_applied_axes;
};

struct RunSummary {
  std::size_t scans = 0;            ///< scans read
  std::size_t scans_processed = 0;  ///< scans that gave a state
  std::size_t imu_samples = 0;
  /// Scans without per-point times, which were made up from the geometry: right for a raw sweep,
  /// a second deskew for clouds deskewed upstream (recording.deskewed; docs/recordings.md).
  std::size_t scans_with_made_up_times = 0;
  /// recording.deskewed: auto judged by the sweeps' seams before the run (sweep_check.hpp);
  /// empty when the configuration set it.
  std::optional<SweepCheck> sweep_check;
  std::size_t keyframes = 0;
  std::size_t lidar_rejected = 0;
  std::size_t lidar_inflated = 0;
  std::size_t map_points = 0;
  std::size_t loop_closures = 0;
  /// Times the odometry rebuilt its local map in the shape the mapping graph gave it, and the
  /// wall time it waited for the mapping thread (MappingConfig::correct_odometry).
  std::size_t local_map_rebuilds = 0;
  double odometry_correction_wait_s = 0.0;
  double duration_s = 0.0;  ///< recording time covered by the states
  double path_length_m = 0.0;
  double mean_ms = 0.0, median_ms = 0.0, p95_ms = 0.0, p99_ms = 0.0, max_ms = 0.0;
  int threads = 0;               ///< worker threads the parallel stages could use
  double wall_time_s = 0.0;      ///< reading, odometry and mapping graph, keyframe files included
  double map_export_s = 0.0;     ///< map.las (and map.ply) from keyframes/ at the end
  double realtime_factor = 0.0;  ///< recording duration / wall time (> 1: faster than the sensor)
  double peak_memory_mb = 0.0;
  std::string initialization;
  /// The odom frame's tilt against gravity as the odometry estimated it at the end, [theta_x;
  /// theta_y] deg: gravity in the odom frame is Exp([theta; 0]) (0, 0, -g). The final
  /// trajectories and the map are turned by Exp(-[theta; 0]) (docs/frames.md); the poses
  /// published live are not.
  Eigen::Vector2d frame_tilt_deg = Eigen::Vector2d::Zero();
  HealthReport health;
  std::optional<RealtimeReport> realtime;           ///< with --realtime only
  std::optional<GeorefRunReport> georef;            ///< when the recording has GNSS fixes
  std::optional<CalibrationRunReport> calibration;  ///< with calibration.at_start
  /// With calibration.track_offset: the lidar-IMU time offset followed through the run
  /// (clock_tracker.hpp); its windows are in clock_offset.csv.
  std::optional<ClockTrackingReport> clock;
  std::optional<io::ouster::LiveStats> live;        ///< taiga run --live: the packets' fate
  /// live.pose_udp / live.foxglove: poses sent; Foxglove clients and messages (and those dropped
  /// for a client too far behind, and kept messages dropped from the history that late clients
  /// receive).
  struct Streams {
    std::size_t poses_sent = 0;
    std::uint64_t foxglove_clients = 0, foxglove_messages = 0, foxglove_dropped = 0,
                  foxglove_history_dropped = 0;
  };
  std::optional<Streams> streams;
  /// With mapping.trees: the stems in trees.csv, the live list's updates and its worker's busy
  /// time during the run, and the final inventory's time after it, s.
  std::optional<std::size_t> trees;
  std::size_t trees_updates = 0;
  double trees_work_s = 0.0;
  double trees_final_s = 0.0;
};

/// Runs the odometry over `recording` and writes the outputs into options.out_dir (created).
/// Throws InputError for unreadable input or an unwritable output directory.
RunSummary runOdometry(const std::filesystem::path& recording, const SystemConfig& config,
                       const RunOptions& options);

/// The same on a live Ouster sensor's UDP packets (config.live, io/ouster/live.hpp), until
/// io::ouster::requestLiveStop() or live.idle_timeout_s without a packet; scans are dropped when
/// more than live.max_queued_scans wait (RunSummary::realtime says how many, and the latency).
RunSummary runLive(const SystemConfig& config, const RunOptions& options);

}  // namespace taiga::pipeline
