#include "taiga/pipeline/run.hpp"

#include <fmt/format.h>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <deque>
#include <optional>
#include <set>
#include <vector>

#include "foxglove_stream.hpp"
#include "online_trees.hpp"
#include "pose_stream.hpp"
#include "recording_feed.hpp"
#include "run_georef.hpp"
#include "run_health.hpp"
#include "run_outputs.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/core/percentile.hpp"
#include "taiga/core/progress.hpp"
#include "taiga/io/moving_boxes.hpp"
#include "taiga/io/ouster/live.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/mapping/map_export.hpp"
#include "taiga/pipeline/self_calibration.hpp"
#include "taiga/pipeline/slam_system.hpp"
#include "taiga/pipeline/thread_limit.hpp"
#include "taiga/view/run_view.hpp"

namespace taiga::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double peakMemoryMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

void createOutputDirectory(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw InputError(
        fmt::format("{}: cannot create the output directory: {}", dir.string(), ec.message()));
}

MovingBoxes movingBoxes(const std::filesystem::path& file) {
  if (file.empty()) return {};
  MovingBoxes boxes = io::readMovingBoxes(file);
  logger().info("{}: moving boxes for {} scans", file.string(), boxes.stamps());
  return boxes;
}

// Lidar-only when configured so, or (auto) when no IMU reading comes with the first 2 s of scans
// (or with all of a shorter recording). The events read to decide are left in `read_ahead`, to
// be handled first (without pacing under --realtime).
bool useLidarOnly(io::Recording& recording, const std::string& imu_use,
                  std::deque<io::RecordingEvent>& read_ahead) {
  bool lidar_only = imu_use == "lidar_only";
  if (imu_use == "auto") {
    constexpr double kImuWait_s = 2.0;
    std::optional<double> first_scan_s;
    lidar_only = true;  // unless an IMU reading comes in time
    while (std::optional<io::RecordingEvent> event = recording.next()) {
      read_ahead.push_back(std::move(*event));
      if (std::holds_alternative<ImuSample>(read_ahead.back())) {
        lidar_only = false;
        break;
      }
      if (!std::holds_alternative<io::Scan>(read_ahead.back())) continue;
      const double t_s = io::eventTime(read_ahead.back());
      if (!first_scan_s) first_scan_s = t_s;
      if (t_s - *first_scan_s >= kImuWait_s) break;
    }
  }
  if (lidar_only)
    logger().info(
        "lidar-only odometry{}: constant-velocity prediction and deskew, odom frame = the first "
        "scan's body frame (not levelled)",
        imu_use == "auto" ? " (no IMU reading with the first 2 s of scans)" : "");
  return lidar_only;
}

/// Feeds the recording to the system: the events read ahead first, then through a reader thread
/// that reads and decodes ahead (at most a few scans), at sensor rate under --realtime.
/// Returns the scans read and, under --realtime, what a live run would have seen.
std::size_t feedRecording(io::Recording& recording, std::deque<io::RecordingEvent> read_ahead,
                          const RunOptions& options, const LiveConfig* live, SlamSystem& slam,
                          ScanLog& scan_log, const HealthLog& health, ClockTracker* clock_tracker,
                          std::optional<RealtimeReport>& realtime) {
  Progress progress("taiga run", 0, "scans", stderr,
                    options.show_progress && isatty(fileno(stderr)));
  std::size_t scans = 0;
  double read_ms_since_scan = 0.0;  // the reader's time since the previous scan, IMU included
  auto handle = [&](io::RecordingEvent& event) {
    auto* scan = std::get_if<io::Scan>(&event);
    if (scan) scan_log.chargeReadTime(scan->index, std::exchange(read_ms_since_scan, 0.0));
    if (scan && scan->times_invented) scan_log.countMadeUpTimes();
    if (scan && clock_tracker != nullptr) clock_tracker->adjust(*scan);
    slam.add(event);
    if (scan) progress.update(++scans, health.progressNote());
    return scan != nullptr;
  };
  for (io::RecordingEvent& event : read_ahead) handle(event);
  constexpr std::size_t kReadAheadScans = 3;
  const auto pacing = live != nullptr    ? RecordingFeed::Pacing::kLive
                      : options.realtime ? RecordingFeed::Pacing::kSensorRate
                                         : RecordingFeed::Pacing::kAsFastAsPossible;
  RecordingFeed feed(recording, pacing,
                     live != nullptr    ? static_cast<std::size_t>(live->max_queued_scans)
                     : options.realtime ? options.realtime_queue_scans
                                        : kReadAheadScans);
  std::vector<double> latencies_ms;
  while (std::optional<RecordingFeed::Delivery> delivery = feed.next()) {
    read_ms_since_scan += delivery->read_ms;
    if (handle(delivery->event)) latencies_ms.push_back(1000.0 * secondsSince(delivery->delivered));
  }
  progress.finish();
  if (pacing != RecordingFeed::Pacing::kAsFastAsPossible)
    realtime = RealtimeReport{.dropped_scans = feed.droppedScans(),
                              .latency_p50_ms = percentile(latencies_ms, 50.0),
                              .latency_p95_ms = percentile(latencies_ms, 95.0),
                              .latency_p99_ms = percentile(latencies_ms, 99.0),
                              .latency_max_ms = percentile(latencies_ms, 100.0)};
  return scans;
}

/// calibration.at_start: the rig's time offset and rotation from the recording's first stretch
/// (self_calibration.hpp), written into `config`; a recording that cannot be calibrated keeps
/// the configured rig and the report says why.
CalibrationRunReport calibrateAtStart(const std::filesystem::path& recording,
                                      SystemConfig& config) {
  CalibrationRunReport report;
  const auto start = Clock::now();
  try {
    const SelfCalibration c = selfCalibrate(recording, config);
    config.rig = c.rig;
    report.passes = c.passes.size();
    report.time_offset_s = c.rig.lidar_time_offset_s;
    report.offset_change_s = c.offset_change_s;
    report.offset_sigma_s = c.last.offset_sigma_s;
    report.offset_observable = c.last.offset_observable;
    report.rotation_change_deg = c.R_change.angle() * kDegPerRad;
    report.rotation_sigma_deg = c.last.rotation_sigma_rad * kDegPerRad;
    report.rotation_observable_axes = calib::axisNames(c.last.rotation_observable);
    report.advice = c.last.advice;
    if (c.lever_arm) {
      report.lever_arm_change_m = c.lever_arm->correction_m;
      report.lever_arm_sigma_m = c.lever_arm->sigma_m;
      report.lever_arm_applied_axes = calib::axisNames(c.lever_arm_applied);
    }
    report.gyro_noise_verdict = calib::toString(c.gyro_noise_verdict.kind);
    report.gyro_noise_text = c.gyro_noise_verdict.text;
    report.gyro_noise_suggested = c.gyro_noise_verdict.suggested;
    if (c.gyro_noise) {
      report.gyro_noise_measured = c.gyro_noise->density_radps_sqrthz;
      report.gyro_noise_sigma = c.gyro_noise->density_sigma;
    }
    if (c.gyro_noise_verdict.kind == calib::NoiseVerdict::Kind::kUnderstated) {
      report.gyro_noise_applied = config.calibration.apply_gyro_noise;
      if (report.gyro_noise_applied) {
        config.odometry.imu.gyro_noise_density = c.gyro_noise_verdict.suggested;
        logger().info("{}; the run uses the measured density", c.gyro_noise_verdict.text);
      } else {
        logger().warn("{}", c.gyro_noise_verdict.text);
      }
    }
  } catch (const std::exception& e) {  // bad input or a pass that failed: the run goes on
    report.skipped = e.what();
    logger().warn("calibration at the start skipped, the configured rig is used: {}", e.what());
  }
  report.wall_time_s = secondsSince(start);
  return report;
}

/// map.las from the keyframes on the map; a segment that was lost and never re-attached lies
/// where dead reckoning put it, so its keyframes go to map_segment_N.las instead of corrupting
/// the map. Returns the points in map.las.
std::uint64_t exportMaps(const mapping::KeyframeStore& store, const mapping::Mapper& mapper,
                         const std::filesystem::path& out, const RunOptions& options) {
  const mapping::PoseGraph& graph = mapper.graph();
  std::set<std::uint64_t> detached;
  for (std::size_t k = 0; k < graph.size(); ++k)
    if (!mapper.attached(k)) detached.insert(graph.segment(k));
  const mapping::MapExportOptions map_options{.voxel_m = options.map_voxel_m,
                                              .write_ply = options.write_ply};
  for (const std::uint64_t segment : detached) {
    mapping::MapExportOptions segment_options = map_options;
    segment_options.keep = [&](std::uint64_t id) { return graph.segment(id) == segment; };
    mapping::exportMap(store, graph.poses(), out / fmt::format("map_segment_{}.las", segment),
                       segment_options);
  }
  mapping::MapExportOptions attached_options = map_options;
  if (!detached.empty())
    attached_options.keep = [&](std::uint64_t id) { return mapper.attached(id); };
  return mapping::exportMap(store, graph.poses(), out / "map.las", attached_options).points_written;
}

/// A live run that got no usable lidar packet says which of the setup's parts is wrong.
void throwIfNoLidarData(const io::ouster::LiveStats& live, const std::string& source,
                        const LiveConfig& config) {
  if (live.lidar_packets == 0 && live.other_datagrams > 0)
    throw InputError(fmt::format(
        "{}: {} datagrams arrived, none of the lidar packet size of {}: the metadata does not "
        "describe this sensor's configuration (profile, columns per packet, beams)",
        source, live.other_datagrams, config.metadata));
  if (live.lidar_packets == 0)
    throw InputError(fmt::format(
        "{}: no lidar packet arrived ({} IMU packets; {}): is the sensor sending to this host "
        "(its udp_dest) and to these ports (live.lidar_port, live.imu_port)?",
        source, live.imu_packets, live.stop_reason));
  if (live.bad_packets == live.lidar_packets)
    throw InputError(fmt::format(
        "{}: every one of the {} lidar packets was refused (CRC, packet type, or another "
        "sensor's serial number than {} names; the first warning above says which)",
        source, live.lidar_packets, config.metadata));
}

bool calibratesAtStart(const SystemConfig& config) {
  return config.calibration.at_start && config.odometry.imu_use != "lidar_only";
}

/// The SLAM system over `recording` (from `recording_path`, or a live sensor's streams when
/// `live` is given), its outputs written into options.out_dir.
RunSummary runRecording(io::Recording& recording, const std::filesystem::path& recording_path,
                        const SystemConfig& config, std::optional<SweepCheck> sweep_check,
                        std::optional<CalibrationRunReport> calibration,
                        const RunOptions& options, io::ouster::LiveCapture* live) {
  const std::filesystem::path& out = options.out_dir;
  std::deque<io::RecordingEvent> read_ahead;
  const bool lidar_only = useLidarOnly(recording, config.odometry.imu_use, read_ahead);
  SlamSystem slam(config, {.keyframe_dir = out / "keyframes",
                           .lidar_only = lidar_only,
                           .moving_boxes_body = movingBoxes(options.moving_boxes_file)});
  TrajectoryRecorder trajectories;
  ScanLog scan_log(out);
  GnssRecorder gnss(config);
  HealthLog health(config.odometry.health);
  slam.addObserver(trajectories);
  slam.addObserver(scan_log);
  slam.addObserver(health);
  slam.addObserver(gnss);
  std::unique_ptr<stream::FoxgloveServer> foxglove;
  std::optional<FoxgloveMapStream> foxglove_map;
  if (!options.view.empty()) {
    foxglove = startFoxglove(options.view, view::liveViewResponse);
    logger().info("viewer on http://{}/", options.view);
    slam.addObserver(foxglove_map.emplace(*foxglove, slam.odometry(), &gnss));
  } else if (!config.live.foxglove.empty()) {
    foxglove = startFoxglove(config.live.foxglove);
    slam.addObserver(foxglove_map.emplace(*foxglove, slam.odometry(), &gnss));
  }
  std::optional<PoseStream> pose_stream;
  if (!config.live.pose_udp.empty() || foxglove) {
    slam.addObserver(
        pose_stream.emplace(config.live.pose_udp, foxglove.get(), config, live == nullptr));
    if (live != nullptr)
      live->setImuTap([&pose_stream, &recording](ImuSample sample) {
        recording.correctGyro(sample);
        pose_stream->imuArrived(sample);
      });
  }
  std::optional<OnlineTrees> online_trees;
  if (config.mapping.trees)
    slam.addObserver(online_trees.emplace(
        slam.keyframes(), out / "trees.csv",
        foxglove_map ? std::function([&](const std::vector<trees::Stem>& stems) {
          foxglove_map->publishTrees(stems);
        })
                     : nullptr));

  std::optional<ClockTracker> clock_tracker;
  if (config.calibration.track_offset && !lidar_only) {
    clock_tracker.emplace(config.calibration, config.rig, [&recording](double offset_s) {
      recording.setLidarTimeOffset(offset_s);
    });
    slam.addObserver(*clock_tracker);
  }

  RunSummary summary;
  const auto wall_start = Clock::now();
  summary.scans = feedRecording(recording, std::move(read_ahead), options,
                                live != nullptr ? &config.live : nullptr, slam, scan_log, health,
                                clock_tracker ? &*clock_tracker : nullptr, summary.realtime);
  if (live != nullptr) {
    live->setImuTap(nullptr);  // before pose_stream goes
    summary.live = live->stats();
  }
  if (pose_stream) summary.streams = RunSummary::Streams{.poses_sent = pose_stream->sent()};
  if (foxglove) {
    const stream::FoxgloveServerStats f = foxglove->stats();
    summary.streams->foxglove_clients = f.connections;
    summary.streams->foxglove_messages = f.messages_sent;
    summary.streams->foxglove_dropped = f.messages_dropped;
    summary.streams->foxglove_history_dropped = f.history_dropped;
  }
  // The mapping thread's last loop closures belong to the processing time; the export does not.
  const mapping::Mapper& mapper = slam.finish();
  summary.wall_time_s = secondsSince(wall_start);
  // The turn SlamSystem::finish levelled the map by; the odometry's trajectory follows below.
  const lie::SO3 R_level_odom = slam.odometry().R_level_odom();
  summary.frame_tilt_deg = -R_level_odom.Log().head<2>() / kRadPerDeg;
  if (!summary.frame_tilt_deg.isZero())
    logger().info(
        "the odom frame was {:.2f} deg off level by the odometry's final estimate; the "
        "trajectories and the map are levelled by it",
        summary.frame_tilt_deg.norm());
  if (clock_tracker) {
    summary.clock = clock_tracker->finish();
    logger().info("clock: {}", summary.clock->text);
    writeClockWindows(out / "clock_offset.csv", summary.clock->windows);
  }
  scan_log.fillSummary(summary);
  summary.health = health.finish();
  std::vector<Reattachment>& reattached = summary.health.reattached;
  for (const mapping::RelocalizationRecord& r : mapper.relocalizationAttempts())
    if (r.attempt.accepted && (reattached.empty() || reattached.back().segment != r.segment))
      reattached.push_back(  // the first link of each segment
          {r.segment, r.t_s, r.attempt.correction_m, r.attempt.correction_deg, r.attempt.overlap});
  if (live != nullptr) throwIfNoLidarData(*summary.live, recording_path.string(), config.live);
  if (trajectories.odometry().empty())
    throw InputError(fmt::format(
        "{}: no scan could be processed ({} scans, {} IMU samples): the odometry needs at least "
        "0.5 s of IMU readings before the scans, or odometry.imu_use: lidar_only",
        recording_path.string(), summary.scans, summary.imu_samples));

  if (online_trees) {
    const auto trees_start = Clock::now();
    summary.trees = online_trees->finish(mapper.graph().poses());
    summary.trees_final_s = secondsSince(trees_start);
    summary.trees_work_s = online_trees->workSeconds();
    summary.trees_updates = online_trees->updates();
  }
  const Trajectory corrected = trajectories.write(out, mapper.graph(), R_level_odom);
  writeLoops(out / "loops.csv", mapper.loopAttempts());
  io::writeTum(out / "keyframes.tum", slam.keyframes().trajectory());
  const auto export_start = Clock::now();
  const std::vector<lie::SE3>& keyframe_poses = mapper.graph().poses();
  summary.map_points = exportMaps(slam.keyframes(), mapper, out, options);
  summary.map_export_s = secondsSince(export_start);
  gnss.writeOnline(out / "georef");
  if (!gnss.input().fixes.empty())
    summary.georef = georeferenceRun(corrected, gnss.input(), config, recording_path.string(),
                                     {.store = slam.keyframes(),
                                      .poses_T_map_body = keyframe_poses,
                                      .voxel_m = options.map_voxel_m},
                                     out);

  summary.loop_closures = mapper.loopClosures();
  summary.odometry_correction_wait_s = slam.correctionWait_s();
  summary.duration_s = trajectories.odometry().endTime() - trajectories.odometry().startTime();
  summary.path_length_m = trajectories.odometry().pathLength();
  summary.realtime_factor =
      summary.wall_time_s > 0.0 ? summary.duration_s / summary.wall_time_s : 0.0;
  summary.peak_memory_mb = peakMemoryMb();
  summary.threads = static_cast<int>(
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  summary.initialization = slam.odometry().initializationNote();
  summary.sweep_check = sweep_check;
  summary.calibration = calibration;
  writeSummary(out / "summary.json", summary, recording_path, mapper.gnssReport());
  return summary;
}

}  // namespace

RunSummary runOdometry(const std::filesystem::path& recording_path, const SystemConfig& configured,
                       const RunOptions& options) {
  createOutputDirectory(options.out_dir);
  const ThreadLimit thread_limit(configured.compute.threads);
  SystemConfig config = configured;
  // Before the calibration, whose passes deskew the scans too.
  const std::optional<SweepCheck> sweep_check = resolveDeskewed(recording_path, config);
  std::optional<CalibrationRunReport> calibration;
  if (calibratesAtStart(config)) {
    if (options.realtime)  // a live sensor gives no stretch to read ahead
      calibration = CalibrationRunReport{
          .skipped =
              "not under --realtime, which replays the recording as a live sensor would "
              "deliver it; calibrate with taiga calibrate first"};
    else
      calibration = calibrateAtStart(recording_path, config);
  }
  io::Recording recording = io::openRecording(recording_path, config.recording, config.rig);
  return runRecording(recording, recording_path, config, sweep_check, calibration, options,
                      nullptr);
}

RunSummary runLive(const SystemConfig& config, const RunOptions& options) {
  if (config.live.metadata.empty())
    throw InputError(
        "live.metadata: a live run needs the sensor's metadata JSON (beam angles, packet "
        "profiles, ports); set it in the configuration");
  createOutputDirectory(options.out_dir);
  const ThreadLimit thread_limit(config.compute.threads);
  io::ouster::LiveCapture capture(
      {.metadata = config.live.metadata,
       .bind_address = config.live.bind_address,
       .lidar_port = static_cast<std::uint16_t>(config.live.lidar_port),
       .imu_port = static_cast<std::uint16_t>(config.live.imu_port),
       .idle_timeout_s = config.live.idle_timeout_s,
       .socket_buffer_bytes = static_cast<int>(config.live.socket_buffer_mb * 1e6)});
  std::optional<CalibrationRunReport> calibration;
  if (calibratesAtStart(config))  // a live sensor gives no stretch to read ahead
    calibration = CalibrationRunReport{
        .skipped =
            "not on a live sensor: calibrate a recording of the rig with taiga calibrate "
            "and give the run its rig.yaml"};
  io::Recording recording = capture.recording(config.rig);
  return runRecording(recording, capture.name(), config, std::nullopt, calibration, options,
                      &capture);
}

}  // namespace taiga::pipeline
