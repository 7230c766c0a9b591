#include "taiga/pipeline/run.hpp"

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

#include "odometry_correction.hpp"
#include "recording_feed.hpp"
#include "run_georef.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/core/progress.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/moving_boxes.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/map_export.hpp"
#include "taiga/mapping/mapper.hpp"
#include "taiga/mapping/trajectory_correction.hpp"
#include "taiga/pipeline/lidar_inertial_odometry.hpp"

namespace taiga::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

std::ofstream openOutput(const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("{}: cannot write", path.string()));
  return out;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double rank = p * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(rank);
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (rank - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

double peakMemoryMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

/// Appends a pose to a trajectory unless it is not after the last one (IMU-rate poses repeat the
/// state times at scan boundaries).
void appendIfLater(Trajectory& trajectory, double t_s, const lie::SE3& pose) {
  if (trajectory.empty() || t_s > trajectory.endTime()) trajectory.append(t_s, pose);
}

Trajectory transformed(const Trajectory& trajectory, const lie::SE3& T_new_old) {
  Trajectory out;
  for (const StampedPose& p : trajectory) out.append(p.t_s, T_new_old * p.pose);
  return out;
}

// GNSS fused in the mapping graph (mapping.gnss_fusion): what became of the fixes and the
// graph's T_enu_world (docs/mapping.md).
nlohmann::ordered_json gnssFusionJson(const mapping::GnssFusionReport& r) {
  nlohmann::ordered_json j = {
      {"fixes", r.total},     {"gated", r.gated}, {"outside_keyframes", r.outside},
      {"waiting", r.waiting}, {"used", r.used},   {"down_weighted", r.down_weighted}};
  if (r.enu_origin)
    j["enu_origin"] = {{"latitude_deg", r.enu_origin->latitude_deg},
                       {"longitude_deg", r.enu_origin->longitude_deg},
                       {"height_ellipsoid_m", r.enu_origin->height_m}};
  if (r.T_enu_world) {
    const Eigen::Matrix4d T = r.T_enu_world->matrix();
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (int i = 0; i < 4; ++i) rows.push_back({T(i, 0), T(i, 1), T(i, 2), T(i, 3)});
    j["T_enu_world"] = rows;
    j["yaw_enu_world_deg"] = std::atan2(T(1, 0), T(0, 0)) * 57.29577951308232;
  }
  return j;
}

void writeSummary(const std::filesystem::path& path, const RunSummary& s,
                  const std::filesystem::path& recording,
                  const std::optional<mapping::GnssFusionReport>& gnss_fusion) {
  nlohmann::ordered_json j = {
      {"recording", recording.string()},
      {"scans", s.scans},
      {"scans_processed", s.scans_processed},
      {"imu_samples", s.imu_samples},
      {"keyframes", s.keyframes},
      {"loop_closures", s.loop_closures},
      {"odometry_corrections",
       {{"local_map_rebuilds", s.local_map_rebuilds}, {"wait_s", s.odometry_correction_wait_s}}},
      {"registration_failures", s.lidar_rejected},
      {"lidar_factors_inflated", s.lidar_inflated},
      {"map_points", s.map_points},
      {"duration_s", s.duration_s},
      {"path_length_m", s.path_length_m},
      {"time_per_scan_ms",
       {{"mean", s.mean_ms}, {"p50", s.median_ms}, {"p95", s.p95_ms}, {"max", s.max_ms}}},
      {"wall_time_s", s.wall_time_s},
      {"map_export_s", s.map_export_s},
      {"realtime_factor", s.realtime_factor},
      {"peak_memory_mb", s.peak_memory_mb},
      {"initialization", s.initialization},
  };
  if (s.realtime) {
    j["realtime"] = {{"dropped_scans", s.realtime->dropped_scans},
                     {"latency_ms",
                      {{"p50", s.realtime->latency_p50_ms},
                       {"p95", s.realtime->latency_p95_ms},
                       {"max", s.realtime->latency_max_ms}}}};
  }
  if (s.georef) {
    const GeorefRunReport& g = *s.georef;
    nlohmann::ordered_json georef = {{"fixes", g.fixes}};
    if (!g.skipped.empty()) {
      georef["skipped"] = g.skipped;
    } else {
      constexpr double kDeg = 57.29577951308232;
      georef.update({{"method", g.method},
                     {"epsg", g.epsg},
                     {"inliers", g.inliers},
                     {"outliers", g.outliers},
                     {"horizontal_rms_m", g.horizontal_rms_m},
                     {"vertical_rms_m", g.vertical_rms_m},
                     {"sigma",
                      {{"east_m", g.sigma[0]},
                       {"north_m", g.sigma[1]},
                       {"up_m", g.sigma[2]},
                       {"roll_deg", g.sigma[3] * kDeg},
                       {"pitch_deg", g.sigma[4] * kDeg},
                       {"yaw_deg", g.sigma[5] * kDeg}}},
                     {"map_export_s", g.map_export_s}});
    }
    j["georef"] = georef;
  }
  if (gnss_fusion) j["gnss_fusion"] = gnssFusionJson(*gnss_fusion);
  openOutput(path) << j.dump(2) << "\n";
}

// Lidar-only when configured so, or (auto) when no IMU reading comes with the first 2 s of
// scans. The events read to decide are left in `read_ahead`, to be handled first (without
// pacing under --realtime).
bool useLidarOnly(io::Recording& recording, const std::string& imu_use,
                  std::deque<io::RecordingEvent>& read_ahead) {
  if (imu_use != "auto") return imu_use == "lidar_only";
  constexpr double kImuWait_s = 2.0;
  std::optional<double> first_scan_s;
  while (std::optional<io::RecordingEvent> event = recording.next()) {
    read_ahead.push_back(std::move(*event));
    if (std::holds_alternative<ImuSample>(read_ahead.back())) return false;
    if (!std::holds_alternative<io::Scan>(read_ahead.back())) continue;
    const double t_s = io::eventTime(read_ahead.back());
    if (!first_scan_s) first_scan_s = t_s;
    if (t_s - *first_scan_s >= kImuWait_s) return true;
  }
  return false;  // too short to tell: the odometry will say what it lacks
}

std::vector<lie::SE3> transformedPoses(const std::vector<lie::SE3>& poses,
                                       const lie::SE3& T_new_old) {
  std::vector<lie::SE3> out;
  out.reserve(poses.size());
  for (const lie::SE3& T_old_body : poses) out.push_back(T_new_old * T_old_body);
  return out;
}

// loops.csv: every loop closure attempt, accepted or not, and why.
void writeLoops(const std::filesystem::path& path,
                const std::vector<mapping::LoopRecord>& attempts) {
  std::ofstream out = openOutput(path);
  out << "t_s,keyframe,candidate,distance_m,search_radius_m,fitness_m2,correction_m,correction_"
         "deg,chi2,accepted,note\n";
  for (const mapping::LoopRecord& record : attempts) {
    const mapping::LoopAttempt& a = record.attempt;
    out << fmt::format("{:.6f},{},{},{:.3f},{:.3f},{:.5f},{:.4f},{:.4f},{:.2f},{},\"{}\"\n",
                       record.t_s, a.current, a.candidate.keyframe, a.candidate.distance_m,
                       a.candidate.search_radius_m, a.registration.fitness_m2, a.correction_m,
                       a.correction_deg, record.chi2, a.accepted ? 1 : 0, a.note);
  }
}

}  // namespace

RunSummary runOdometry(const std::filesystem::path& recording_path, const SystemConfig& config,
                       const RunOptions& options) {
  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec)
    throw InputError(fmt::format("{}: cannot create the output directory: {}",
                                 options.out_dir.string(), ec.message()));

  io::Recording recording = io::openRecording(recording_path, config.recording, config.rig);
  LidarInertialOdometry odometry(config.odometry, config.rig);
  if (!options.moving_boxes_file.empty()) {
    MovingBoxes boxes = io::readMovingBoxes(options.moving_boxes_file);
    logger().info("{}: moving boxes for {} scans", options.moving_boxes_file.string(),
                  boxes.stamps());
    odometry.setMovingBoxes(std::move(boxes));
  }

  std::ofstream timing = openOutput(options.out_dir / "timing.csv");
  timing << "t_s,read_ms,deskew_ms,filter_ms,registration_ms,optimization_ms,map_ms,total_ms\n";
  std::ofstream scans = openOutput(options.out_dir / "scans.csv");
  scans << "t_s,scan,lidar_factor,fitness_m2,iterations,converged,inliers,hessian_condition,source_"
           "points,keyframe,note\n";
  // Keyframe scans go to disk in the body frame as they are made (memory stays flat); the map is
  // exported from them at the end, with the final poses. Only the registration-resolution copy
  // that loop closure registers stays in RAM.
  mapping::KeyframeStore keyframe_store = mapping::KeyframeStore::create(
      options.out_dir / "keyframes", {.registration_voxel_m = config.odometry.voxel_size_m});
  // The mapping graph runs beside the odometry and corrects the keyframe poses at the end. With
  // mapping.correct_odometry the live poses follow its corrections two keyframes later (below).
  // After every keyframe it rewrites keyframes/poses.tum, so `taiga export-map` gives the map
  // so far.
  const bool correct_odometry = config.mapping.correct_odometry;
  mapping::MappingThread mapping_thread(
      config.mapping, config.odometry, keyframe_store,
      {.write_live_poses = true,
       .snapshot_keyframes =
           correct_odometry ? static_cast<std::size_t>(config.odometry.local_map_keyframes) : 0});
  std::vector<double> keyframe_times_s;
  // The live georeference of each scan's pose, from the fixes received so far (georef/online.hpp).
  std::optional<georef::OnlineGeoreferencer> online_georef;
  std::vector<OnlineGridPose> online_poses;

  Trajectory trajectory, trajectory_imu;
  RunSummary summary;
  std::vector<double> totals_ms;
  // The reader thread's time to read and decode the events since the previous scan (IMU
  // readings included), charged to the scan.
  double read_ms_since_scan = 0.0, scan_read_ms = 0.0;
  Progress progress("taiga run", 0, "scans", stderr,
                    options.show_progress && isatty(fileno(stderr)));
  const auto wall_start = Clock::now();

  // The graph's corrections fed back into the odometry (odometry_correction.hpp): the live poses
  // are published in the graph's map frame (trajectory_online.tum); every other output is in the
  // odometry's own continuous frame, which the graph corrects at the end.
  OdometryCorrection correction(static_cast<std::size_t>(config.odometry.local_map_keyframes));
  Trajectory trajectory_online;
  double correction_wait_s = 0.0;
  auto consume = [&](const ScanOutcome& outcome) {
    ++summary.scans_processed;
    if (outcome.world_correction) {  // levelling, before any correction from the graph
      const lie::SE3& T_new_old = *outcome.world_correction;
      trajectory = transformed(trajectory, T_new_old);
      trajectory_imu = transformed(trajectory_imu, T_new_old);
      trajectory_online = transformed(trajectory_online, T_new_old);
      keyframe_store.setPoses(transformedPoses(keyframe_store.poses(), T_new_old));
      correction.changeOdomFrame(T_new_old);
      mapping_thread.changeWorldFrame(T_new_old);
      if (online_georef) online_georef->changeWorldFrame(T_new_old);
    }
    appendIfLater(trajectory_online, outcome.t_s, correction.T_map_odom() * outcome.T_world_body);
    if (online_georef) {
      online_georef->addPose(outcome.t_s, outcome.T_world_body);
      if (auto grid = online_georef->toGrid(outcome.t_s, outcome.T_world_body))
        online_poses.push_back(
            {*grid, online_georef->estimate()->fit.sigma, online_georef->estimate()->fixes});
    }
    appendIfLater(trajectory, outcome.t_s, outcome.T_world_body);
    for (const StampedPose& p : outcome.imu_rate_poses)
      appendIfLater(trajectory_imu, p.t_s, p.pose);
    appendIfLater(trajectory_imu, outcome.t_s, outcome.T_world_body);
    summary.lidar_rejected += outcome.lidar == LidarFactor::kRejected;
    summary.lidar_inflated += outcome.lidar == LidarFactor::kInflated;
    totals_ms.push_back(outcome.timing.total_ms);
    const ScanTiming& t = outcome.timing;
    timing << fmt::format("{:.6f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f}\n", outcome.t_s,
                          scan_read_ms, t.deskew_ms, t.filter_ms, t.registration_ms,
                          t.optimization_ms, t.map_ms, t.total_ms);
    const registration::RegistrationResult& r = outcome.registration;
    scans << fmt::format("{:.6f},{},{},{:.5f},{},{},{},{:.4g},{},{},\"{}\"\n", outcome.t_s,
                         outcome.scan_index, lidarFactorName(outcome.lidar), r.fitness_m2,
                         r.iterations, r.converged ? 1 : 0, r.num_inliers, r.hessian_condition,
                         outcome.source_points, outcome.keyframe ? 1 : 0, outcome.lidar_note);
    if (outcome.keyframe_cloud_in_body &&
        (keyframe_store.empty() ||
         outcome.t_s > keyframe_store.info(keyframe_store.size() - 1).t_s)) {
      const std::uint64_t id =
          keyframe_store.add(outcome.t_s, outcome.T_world_body, *outcome.keyframe_cloud_in_body);
      mapping_thread.addKeyframe(id, outcome.t_s, outcome.T_world_body);
      keyframe_times_s.push_back(outcome.t_s);
      correction.addKeyframe(outcome.t_s, outcome.T_world_body);
      ++summary.keyframes;
      // The graph as it was after keyframe id - kDelayKeyframes; waits if the mapping thread is
      // behind, so the correction depends on the data, not on timing.
      if (correct_odometry && odometry.levelled() && id >= OdometryCorrection::kDelayKeyframes) {
        const auto wait_start = Clock::now();
        const std::optional<mapping::GraphSnapshot> snapshot =
            mapping_thread.waitForSnapshot(id - OdometryCorrection::kDelayKeyframes);
        correction_wait_s += std::chrono::duration<double>(Clock::now() - wait_start).count();
        if (snapshot && correction.apply(*snapshot, !odometry.lidarOnly(), odometry))
          ++summary.local_map_rebuilds;
      }
    }
  };
  // GNSS fixes are kept for the georeferencing at the end (and the IMU's absolute orientation,
  // which only the pf6 fit uses).
  georef::GnssInput gnss{.from_recording = true};
  const bool keep_imu_orientation = config.georef.method == "pf6";
  // Returns whether the event was a scan.
  auto handle = [&](const io::RecordingEvent& event) {
    if (const auto* imu = std::get_if<ImuSample>(&event)) {
      odometry.addImu(*imu);
      ++summary.imu_samples;
      if (keep_imu_orientation && imu->orientation) gnss.imu_with_orientation.push_back(*imu);
      return false;
    }
    if (const auto* fix = std::get_if<GnssFix>(&event)) {
      gnss.fixes.push_back(*fix);
      if (config.mapping.gnss_fusion) mapping_thread.addGnssFix(*fix);
      if (!online_georef) online_georef.emplace(georef::settingsFrom(config.georef));
      online_georef->addFix(*fix);
      return false;
    }
    const auto* scan = std::get_if<io::Scan>(&event);
    if (!scan) return false;
    ++summary.scans;
    scan_read_ms = std::exchange(read_ms_since_scan, 0.0);
    const std::optional<ScanOutcome> outcome = odometry.addScan(*scan);
    progress.update(summary.scans);
    if (std::optional<ScanOutcome> first = odometry.takeFirstOutcome()) consume(*first);
    if (outcome) consume(*outcome);
    return true;
  };
  std::deque<io::RecordingEvent> read_ahead;
  const bool lidar_only = useLidarOnly(recording, config.odometry.imu_use, read_ahead);
  if (lidar_only) {
    logger().info(
        "lidar-only odometry{}: constant-velocity prediction and deskew, world frame = "
        "the first scan's body frame (not levelled)",
        config.odometry.imu_use == "auto" ? " (no IMU reading with the first 2 s of scans)" : "");
  }
  odometry.setLidarOnly(lidar_only);
  for (const io::RecordingEvent& event : read_ahead) handle(event);
  read_ahead.clear();
  // A reader thread reads and decodes ahead (at most a few scans), at sensor rate under
  // --realtime. read_ms is its time, which now overlaps with the processing.
  constexpr std::size_t kReadAheadScans = 3;
  RecordingFeed feed(recording,
                     options.realtime ? RecordingFeed::Pacing::kSensorRate
                                      : RecordingFeed::Pacing::kAsFastAsPossible,
                     options.realtime ? options.realtime_queue_scans : kReadAheadScans);
  std::vector<double> latencies_ms;
  while (std::optional<RecordingFeed::Delivery> delivery = feed.next()) {
    read_ms_since_scan += delivery->read_ms;
    if (handle(delivery->event)) {
      latencies_ms.push_back(
          std::chrono::duration<double, std::milli>(Clock::now() - delivery->delivered).count());
    }
  }
  if (options.realtime) {
    summary.realtime = RealtimeReport{.dropped_scans = feed.droppedScans(),
                                      .latency_p50_ms = percentile(latencies_ms, 0.5),
                                      .latency_p95_ms = percentile(latencies_ms, 0.95),
                                      .latency_max_ms = percentile(latencies_ms, 1.0)};
  }
  progress.finish();
  // The mapping thread's last loop closures belong to the processing time; the export does not.
  const mapping::Mapper& mapper = mapping_thread.finish();
  summary.wall_time_s = std::chrono::duration<double>(Clock::now() - wall_start).count();

  if (trajectory.empty()) {
    throw InputError(
        fmt::format("{}: no scan could be processed ({} scans, {} IMU samples): the odometry needs "
                    "at least 0.5 s of IMU readings before the scans, or odometry.imu_use: "
                    "lidar_only",
                    recording_path.string(), summary.scans, summary.imu_samples));
  }
  // The odometry in its continuous frame, its live poses as published, then every pose corrected
  // by the mapping graph.
  io::writeTum(options.out_dir / "trajectory_odometry.tum", trajectory);
  io::writeTum(options.out_dir / "trajectory_online.tum", trajectory_online);
  summary.odometry_correction_wait_s = correction_wait_s;
  const Trajectory corrected =
      mapping::correctedTrajectory(trajectory, mapper.graph(), keyframe_times_s);
  io::writeTum(options.out_dir / "trajectory.tum", corrected);
  io::writeTum(options.out_dir / "trajectory_imu.tum",
               mapping::correctedTrajectory(trajectory_imu, mapper.graph(), keyframe_times_s));
  writeLoops(options.out_dir / "loops.csv", mapper.loopAttempts());
  summary.loop_closures = mapper.loopClosures();
  const std::vector<lie::SE3>& keyframe_poses = mapper.graph().poses();
  keyframe_store.setPoses(keyframe_poses);
  keyframe_store.writePoses();
  io::writeTum(options.out_dir / "keyframes.tum", keyframe_store.trajectory());
  const auto export_start = Clock::now();
  const mapping::MapExportSummary map =
      mapping::exportMap(keyframe_store, keyframe_poses, options.out_dir / "map.las",
                         {.voxel_m = options.map_voxel_m, .write_ply = options.write_ply});
  summary.map_points = map.points_written;
  summary.map_export_s = std::chrono::duration<double>(Clock::now() - export_start).count();
  if (!online_poses.empty()) {
    writeOnlineGeoreference(options.out_dir / "georef", online_poses, config.georef.epsg);
  }
  if (!gnss.fixes.empty()) {
    summary.georef = georeferenceRun(corrected, gnss, config, recording_path.string(),
                                     {.store = keyframe_store,
                                      .poses_T_world_body = keyframe_poses,
                                      .voxel_m = options.map_voxel_m},
                                     options.out_dir);
  }

  summary.duration_s = trajectory.endTime() - trajectory.startTime();
  summary.path_length_m = trajectory.pathLength();
  summary.mean_ms = totals_ms.empty() ? 0.0
                                      : std::accumulate(totals_ms.begin(), totals_ms.end(), 0.0) /
                                            totals_ms.size();
  summary.median_ms = percentile(totals_ms, 0.5);
  summary.p95_ms = percentile(totals_ms, 0.95);
  summary.max_ms = totals_ms.empty() ? 0.0 : *std::max_element(totals_ms.begin(), totals_ms.end());
  summary.realtime_factor =
      summary.wall_time_s > 0.0 ? summary.duration_s / summary.wall_time_s : 0.0;
  summary.peak_memory_mb = peakMemoryMb();
  summary.initialization = odometry.initializationNote();
  writeSummary(options.out_dir / "summary.json", summary, recording_path, mapper.gnssReport());
  return summary;
}

}  // namespace taiga::pipeline
