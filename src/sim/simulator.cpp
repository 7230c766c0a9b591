#include "taiga/sim/simulator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/os.h>

#include "machine_boxes_output.hpp"
#include "outputs.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/io/rosbag.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/sim/random.hpp"
#include "ouster_capture_output.hpp"
#include "truth_outputs.hpp"

namespace taiga::sim {
namespace {
/// Beyond the loop, the plot extends this far: about the useful range of the lidar, m.
constexpr double kPlotMargin_m = 35.0;

/// Lidar stamp - motion time of a scan starting at motion time t_start_s: the recording epoch,
/// minus the rig's time offset (rig.lidar_time_offset_s puts lidar times on the IMU clock, whose
/// stamps are motion time + epoch), plus the drift of the lidar's clock. The drift within one
/// scan (5 us at 50 ppm) is neglected.
double lidarClockOffset_s(const RigErrorParams& rig, double t_start_s) {
  if (rig.lidar_time_offset_s == 0.0 && rig.lidar_clock_drift_ppm == 0.0) return kRecordingEpoch_s;
  return kRecordingEpoch_s - rig.lidar_time_offset_s + rig.lidar_clock_drift_ppm * 1e-6 * t_start_s;
}

/// The true pose of the lidar at a time of the lidar's clock.
auto lidarPoseAt(const WalkingMotion& motion, const lie::SE3& T_body_lidar, double lidar_clock_s) {
  return [&motion, T_body_lidar, lidar_clock_s](double t_lidar_s) {
    return motion.at(t_lidar_s - lidar_clock_s).T_world_body * T_body_lidar;
  };
}

/// A scan as a front end that deskews upstream republishes it: every point moved, with the true
/// motion, into the lidar frame at the scan's start (the header stamp), and no per-point times.
void deskewWithTruth(io::Scan& scan, const WalkingMotion& motion, const lie::SE3& T_body_lidar,
                     double lidar_clock_s) {
  PointCloud& cloud = scan.cloud_in_lidar;
  const auto T_world_lidar = lidarPoseAt(motion, T_body_lidar, lidar_clock_s);
  const lie::SE3 T_start_world = T_world_lidar(scan.t_start_s).inverse();
  lie::SE3 T_start_point;
  double t_cached = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.times_s[i] != t_cached) {  // one pose per column: its points share a time
      t_cached = cloud.times_s[i];
      T_start_point = T_start_world * T_world_lidar(t_cached);
    }
    cloud.positions[i] = T_start_point * cloud.positions[i];
  }
  cloud.times_s.clear();
  cloud.rings.clear();
  cloud.columns.clear();
}

/// faults.packet_burst_*: the burst's scans lose that share of their 16-column packets (as
/// LidarSimulator's own packet loss, on the finished cloud).
void dropPacketsOfBurst(io::Scan& scan, const FaultParams& f, double t_start_s, double period_s,
                        std::uint64_t seed) {
  const double end_s = f.packet_burst_start_s + f.packet_burst_scans * period_s;
  if (f.packet_burst_scans == 0 || t_start_s < f.packet_burst_start_s - 1e-9 ||
      t_start_s >= end_s - 1e-9)
    return;
  PointCloud& cloud = scan.cloud_in_lidar;
  if (cloud.columns.size() != cloud.size()) return;  // the simulator always writes columns
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::uint64_t packet = cloud.columns[i] / 16;
    if (hashUniform(seed, scan.index, packet, 105) >= f.packet_burst_loss) kept.push_back(i);
  }
  cloud = cloud.select(kept);
}

/// faults.splice_*: the scan at motion time t_start_s replaced by the one simulated at
/// splice_from_s (another place), stamped as the one it replaces.
io::Scan splicedScan(const Simulation& sim, std::uint64_t index, double t_start_s,
                     double lidar_clock_s) {
  const LidarSimulator& lidar = sim.lidar();
  const FaultParams& f = sim.scenario().faults;
  const auto from =
      static_cast<std::uint64_t>(std::llround(f.splice_from_s / lidar.scanPeriod_s()));
  const double t_from_s = static_cast<double>(from) * lidar.scanPeriod_s();
  const double clock_from_s = lidarClockOffset_s(sim.scenario().rig, t_from_s);
  io::Scan scan = lidar.simulateScan(sim.scene(), sim.motion(), from, t_from_s, clock_from_s);
  const double shift_s = (t_start_s + lidar_clock_s) - (t_from_s + clock_from_s);
  scan.index = index;
  scan.t_start_s += shift_s;
  scan.t_end_s += shift_s;
  for (double& t : scan.cloud_in_lidar.times_s) t += shift_s;
  return scan;
}

/// faults.open_field_*: a scan that starts in the window keeps only its ground returns.
void clearTheForest(io::Scan& scan, const Simulation& sim, double t_start_s, double lidar_clock_s) {
  const FaultParams& f = sim.scenario().faults;
  if (f.open_field_s <= 0.0 || t_start_s < f.open_field_start_s - 1e-9 ||
      t_start_s >= f.open_field_start_s + f.open_field_s - 1e-9)
    return;
  constexpr double kAboveGround_m = 0.3;
  PointCloud& cloud = scan.cloud_in_lidar;
  if (cloud.times_s.size() != cloud.size()) return;  // the simulator always writes times
  const auto T_world_lidar = lidarPoseAt(sim.motion(), sim.lidar().T_body_lidar(), lidar_clock_s);
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p_world = T_world_lidar(cloud.times_s[i]) * cloud.positions[i];
    if (p_world.z() - sim.scene().terrain().height(p_world.x(), p_world.y()) <= kAboveGround_m)
      kept.push_back(i);
  }
  cloud = cloud.select(kept);
}

bool isSplicedScan(const FaultParams& f, double t_start_s, double period_s) {
  return f.splice_at_s > 0.0 && std::abs(t_start_s - f.splice_at_s) < 0.5 * period_s;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

Simulation::Simulation(const Scenario& scenario, double duration_s, std::uint64_t seed)
    : scenario_(scenario), duration_s_(duration_s), seed_(seed) {
  motion_ = std::make_unique<WalkingMotion>(scenario.motion, duration_s, seed,
                                            Terrain(scenario.forest, seed));
  SceneLayout layout;
  layout.center_world = motion_->loopCenter();
  layout.half_size_m = motion_->loopHalfExtent_m() + kPlotMargin_m;
  layout.keep_out_path = motion_->loopPolyline(0.5);
  scene_ = std::make_unique<Scene>(scenario.forest, seed, std::move(layout));
  lidar_ =
      std::make_unique<LidarSimulator>(scenario.lidar, loadLidarGeometry(scenario.lidar), seed);
}

std::size_t Simulation::scanCount() const {
  return static_cast<std::size_t>(std::floor(duration_s_ / lidar_->scanPeriod_s() + 1e-9));
}

SimulationSummary writeSimulation(const Simulation& simulation,
                                  const std::filesystem::path& out_dir,
                                  const std::function<void(std::size_t, std::size_t)>& on_scan) {
  const auto start = std::chrono::steady_clock::now();
  std::filesystem::create_directories(out_dir);
  const Scenario& scenario = simulation.scenario();
  const WalkingMotion& motion = simulation.motion();
  const Scene& scene = simulation.scene();
  const LidarSimulator& lidar = simulation.lidar();

  SimulationSummary summary;
  summary.trees = scene.trees().size();
  summary.scene = scene.stats();
  summary.min_points_per_scan = std::numeric_limits<std::size_t>::max();

  // Truth that needs no sensor data first, so that a bad georef_epsg fails before the long work.
  detail::writeGeorefTruthYaml(out_dir / "georef_truth.yaml", simulation);
  detail::writeTreesCsv(out_dir / "trees.csv", scene);
  detail::writeScenarioYaml(out_dir / "scenario.yaml", simulation);
  io::BagWriter bag(out_dir / "recording.bag");
  ImuSimulator imu(scenario.imu, simulation.seed(), scenario.gnss.world_yaw_deg);
  GnssSimulator gnss(scenario.gnss, simulation.seed());
  std::optional<detail::OusterCaptureWriter> capture;
  if (!scenario.output.pcap_profile.empty())
    capture.emplace(out_dir, detail::simulatedSensorInfo(scenario.lidar, lidar.geometry(),
                                                         scenario.output.pcap_profile,
                                                         simulation.seed()));
  Trajectory ground_truth;
  // Each fix's true error and sigma (docs/simulator.md), for benchmarks of the georeferencing.
  std::optional<fmt::ostream> gnss_truth;
  if (scenario.output.gnss) {
    gnss_truth.emplace(fmt::output_file((out_dir / "gnss_truth.csv").string()));
    gnss_truth->print(
        "t_s,error_east_m,error_north_m,error_up_m,sigma_horizontal_m,sigma_vertical_m,multipath,"
        "outage\n");
  }
  auto emitUntil = [&](double t_end_s) {
    while (imu.nextTime_s() <= t_end_s) {
      const double t = imu.nextTime_s();
      const ImuSample sample = imu.next(motion, kRecordingEpoch_s);
      const FaultParams& f = scenario.faults;  // a gap: the sample is drawn, not written
      const bool gap = t >= f.imu_gap_start_s && t < f.imu_gap_start_s + f.imu_gap_s;
      if (scenario.output.imu && !gap) {
        bag.writeImu(kImuTopic, "os_imu", sample);
        if (capture) capture->writeImu(sample, t + kRecordingEpoch_s);
        ++summary.imu_samples;
      }
      // The truth at the IMU's instants (not its jittered stamps).
      ground_truth.append(t + kRecordingEpoch_s, motion.at(t).T_world_body);
    }
    while (gnss.nextTime_s() <= t_end_s) {
      const auto fix = gnss.next(motion, scene, kRecordingEpoch_s);
      if (!scenario.output.gnss) continue;
      const GnssSimulator::Truth& truth = gnss.lastTruth();
      gnss_truth->print("{},{},{},{},{},{},{},{}\n", truth.t_s, truth.error_enu_m.x(),
                        truth.error_enu_m.y(), truth.error_enu_m.z(), truth.sigma_horizontal_m,
                        truth.sigma_vertical_m, truth.multipath ? 1 : 0, truth.outage ? 1 : 0);
      if (fix) {
        bag.writeGnss(kGnssTopic, "gnss", *fix);
        ++summary.gnss_fixes;
      }
    }
  };

  std::optional<detail::MachineBoxesWriter> machine_boxes;  // harvester: crop boxes per scan
  if (const HarvesterMachine* machine = motion.machine())
    machine_boxes.emplace(out_dir / "machine_boxes.csv", *machine);
  const OutputParams& output = scenario.output;
  const std::size_t scans = simulation.scanCount();
  const io::ScanGrid grid{static_cast<std::uint32_t>(lidar.rows()),
                          static_cast<std::uint32_t>(lidar.columns())};
  for (std::size_t k = 0; k < scans; ++k) {
    if (k % static_cast<std::size_t>(output.scan_stride) != 0) {
      if (on_scan) on_scan(k + 1, scans);
      continue;
    }
    const double t_start = static_cast<double>(k) * lidar.scanPeriod_s();
    const double lidar_clock_s = lidarClockOffset_s(scenario.rig, t_start);
    io::Scan scan = isSplicedScan(scenario.faults, t_start, lidar.scanPeriod_s())
                        ? splicedScan(simulation, k, t_start, lidar_clock_s)
                        : lidar.simulateScan(scene, motion, k, t_start, lidar_clock_s);
    dropPacketsOfBurst(scan, scenario.faults, t_start, lidar.scanPeriod_s(), simulation.seed());
    clearTheForest(scan, simulation, t_start, lidar_clock_s);
    const double t_end = scan.t_end_s - lidar_clock_s;  // motion time: the scan is complete
    emitUntil(t_end);
    if (scan.cloud_in_lidar.empty()) {  // every packet lost: the driver publishes nothing
      if (on_scan) on_scan(k + 1, scans);
      continue;
    }
    if (capture)  // the raw scan, before a deskewed layout moves its points
      capture->writeScan(scan, static_cast<std::uint16_t>(k),
                         kRecordingEpoch_s - lidar_clock_s);
    if (output.point_layout == "velodyne") {
      bag.writeScanAs(io::ScanLayout::kVelodyne, kLidarTopic, "velodyne", scan);
    } else if (output.point_layout == "deskewed") {
      deskewWithTruth(scan, motion, lidar.T_body_lidar(), lidar_clock_s);
      bag.writeScanAs(io::ScanLayout::kXyzi, kLidarTopic, "os_sensor", scan);
    } else if (output.point_layout == "untimed") {
      bag.writeScanAs(io::ScanLayout::kXyzi, kLidarTopic, "os_sensor", scan);
    } else {
      bag.writeScan(kLidarTopic, "os_sensor", scan, grid);
    }
    if (machine_boxes) machine_boxes->writeScan(scan.t_start_s, t_start, t_end);
    const std::size_t n = scan.cloud_in_lidar.size();
    summary.points += n;
    summary.min_points_per_scan = std::min(summary.min_points_per_scan, n);
    summary.max_points_per_scan = std::max(summary.max_points_per_scan, n);
    ++summary.scans;
    if (on_scan) on_scan(k + 1, scans);
  }
  emitUntil(simulation.duration_s());
  bag.close();
  if (capture) capture->close();
  if (summary.scans == 0) summary.min_points_per_scan = 0;
  summary.path_length_m = ground_truth.size() > 1 ? ground_truth.pathLength() : 0.0;

  io::writeTum(out_dir / "groundtruth.tum", ground_truth);
  detail::writeRigYaml(out_dir / "rig.yaml", simulation, detail::RigView::kStated);
  detail::writeRigYaml(out_dir / "rig_truth.yaml", simulation, detail::RigView::kTrue);
  summary.simulate_s = secondsSince(start);
  detail::writeSceneJson(out_dir / "scene.json", simulation, summary);
  return summary;
}

}  // namespace taiga::sim
