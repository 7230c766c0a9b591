// The whole odometry on simulated forest walks that start while moving, against the simulator's
// ground truth. The handheld walks pause, bob, sway and turn at up to 90 deg/s. A broken deskew,
// initialization, gravity alignment, registration or IMU factor fails these bounds by a wide
// margin.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "../support/temp_dir.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/eval/evaluate.hpp"
#include "taiga/eval/health_split.hpp"
#include "taiga/eval/map_sharpness.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/io/rosbag.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/mapper.hpp"
#include "taiga/pipeline/run.hpp"
#include "taiga/sim/realism.hpp"
#include "taiga/sim/scenario_yaml.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::pipeline {
namespace {

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct ScenarioRun {
  RunSummary summary;
  eval::MapSharpness map_sharpness;      ///< map.las against the simulated scene
  eval::EvalResult evaluation;           ///< trajectory.tum: corrected by the mapping graph
  eval::EvalResult odometry_evaluation;  ///< trajectory_odometry.tum: the odometry alone
  eval::EvalResult
      online_evaluation;  ///< trajectory_online.tum: as published, corrections included
};

/// How the recording is made and which rig the run is told.
struct RunSetup {
  bool crop_machine = false;          ///< crop the harvester's machine with its per-scan boxes
  std::string realism = "ideal";      ///< simulate --realism
  std::string overrides;              ///< scenario fields (YAML) applied after the realism
  std::string rig_file = "rig.yaml";  ///< as its user would write it, or rig_truth.yaml
  bool calibrate_at_start = false;    ///< calibration.at_start (docs/calibration.md)
  int beams = 64;                     ///< lidar beams; 0: the scenario's (or overrides') own
  /// recording.deskewed; auto (the default) judges clouds without per-point times by their seams
  RecordingConfig::Deskewed deskewed = RecordingConfig::Deskewed::kAuto;
  bool lidar_only = false;            ///< odometry.imu_use: lidar_only
  /// calibration.track_offset; empty: as the rig file says
  std::optional<bool> track_offset;
  /// odometry.method (ndt, d2d, gicp); empty: as the rig file says
  std::string method;
};

// Simulates `scenario_name`, by default with 64 of the OS0-128's beams (the same geometry, a
// faster test), runs the odometry on it with the rig `setup` names and evaluates the trajectory
// against the ground truth.
ScenarioRun simulateAndRun(const std::string& scenario_name, double duration_s, std::uint64_t seed,
                           const std::filesystem::path& dir, const RunSetup& setup = {}) {
  sim::Scenario scenario = sim::scenarioByName(scenario_name);
  sim::applyRealism(setup.realism, scenario);
  if (!setup.overrides.empty())
    sim::applyScenarioOverridesText(setup.overrides, "test overrides", scenario);
  if (setup.beams > 0) scenario.lidar.beams = setup.beams;
  const sim::Simulation simulation(scenario, duration_s, seed);
  if (!std::filesystem::exists(dir / "recording" / "recording.bag"))
    sim::writeSimulation(simulation, dir / "recording");

  SystemConfig config;
  io::readConfigYaml(dir / "recording" / setup.rig_file, config);
  config.calibration.at_start = setup.calibrate_at_start;
  config.recording.deskewed = setup.deskewed;
  if (setup.lidar_only) config.odometry.imu_use = "lidar_only";
  if (setup.track_offset) config.calibration.track_offset = *setup.track_offset;
  if (!setup.method.empty()) config.odometry.method = setup.method;
  validateAll(config);
  const std::filesystem::path run_dir =
      dir /
      ("run_" + std::filesystem::path(setup.rig_file).stem().string() +
       (setup.calibrate_at_start ? "_calibrated" : "") + (setup.lidar_only ? "_lidar_only" : "") +
       (setup.track_offset == false ? "_untracked" : "") +
       (setup.method.empty() ? "" : "_" + setup.method));
  RunOptions options{.out_dir = run_dir, .show_progress = false};
  if (setup.crop_machine) options.moving_boxes_file = dir / "recording" / "machine_boxes.csv";
  ScenarioRun run;
  run.summary = runOdometry(dir / "recording" / "recording.bag", config, options);
  const Trajectory truth = io::readTum(dir / "recording" / "groundtruth.tum");
  run.evaluation = eval::evaluate(io::readTum(run_dir / "trajectory.tum"), truth, {});
  run.odometry_evaluation =
      eval::evaluate(io::readTum(run_dir / "trajectory_odometry.tum"), truth, {});
  run.online_evaluation = eval::evaluate(io::readTum(run_dir / "trajectory_online.tum"), truth, {});
  // Map sharpness (issue 7): 100k points of map.las, in the truth frame by the ATE's alignment.
  io::LasReader map(run_dir / "map.las");
  const PointCloud sample = map.readStrided(std::max<std::uint64_t>(1, map.pointCount() / 100000));
  run.map_sharpness =
      eval::computeMapSharpness(sample.positions, map.pointCount(), run.evaluation.transform,
                                [&](const Eigen::Vector3d& p_ref, double max_m) {
                                  return simulation.scene().distanceToSurface(p_ref, max_m);
                                });
  ::testing::Test::RecordProperty("map_sharpness_rms_m", std::to_string(run.map_sharpness.rms_m));
  ::testing::Test::RecordProperty("ape_rmse_m",
                                  std::to_string(run.evaluation.ape.translation_m.rmse));
  ::testing::Test::RecordProperty("drift_percent",
                                  std::to_string(run.evaluation.drift.drift_percent));
  ::testing::Test::RecordProperty("odometry_ape_rmse_m",
                                  std::to_string(run.odometry_evaluation.ape.translation_m.rmse));
  ::testing::Test::RecordProperty("odometry_drift_percent",
                                  std::to_string(run.odometry_evaluation.drift.drift_percent));
  ::testing::Test::RecordProperty("online_ape_rmse_m",
                                  std::to_string(run.online_evaluation.ape.translation_m.rmse));
  ::testing::Test::RecordProperty("local_map_rebuilds",
                                  std::to_string(run.summary.local_map_rebuilds));
  ::testing::Test::RecordProperty("loop_closures", std::to_string(run.summary.loop_closures));
  ::testing::Test::RecordProperty("path_m", std::to_string(run.summary.path_length_m));
  return run;
}

// The mapping graph built again over a finished run's keyframes (their times from the store,
// their odometry poses from trajectory_odometry.tum), with `verify_loop` checking the loops.
struct MappingReplay {
  std::vector<lie::SE3> poses;
  std::vector<mapping::LoopRecord> attempts;
};
MappingReplay replayMapping(const std::filesystem::path& run_dir, const SystemConfig& config,
                            const mapping::LoopVerifier& verify_loop) {
  const mapping::KeyframeStore store = mapping::KeyframeStore::open(
      run_dir / "keyframes", {.registration_voxel_m = config.odometry.voxel_size_m});
  const Trajectory odometry = io::readTum(run_dir / "trajectory_odometry.tum");
  mapping::Mapper mapper(config.mapping, config.odometry, store, verify_loop);
  for (std::uint64_t id = 0; id < store.size(); ++id) {
    const double t_s = store.info(id).t_s;
    mapper.addKeyframe(id, t_s, odometry.poseAt(t_s));
  }
  mapper.finish();
  return {mapper.graph().poses(), mapper.loopAttempts()};
}

double largestDifference_m(const std::vector<lie::SE3>& a, const std::vector<lie::SE3>& b) {
  double largest = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    largest = std::max(largest, (a[i].translation() - b[i].translation()).norm());
  return largest;
}

// Issue 7: a false loop does not corrupt the map. The first loop that verifies is replaced by a
// wrong one that registration accepted (1.5 m sideways and 3 deg off, as look-alike stems can
// give); the chi^2 consistency check must refuse it, leaving the map exactly as if that attempt
// had failed. With the check off, the same injection moves the map: the test can tell.
void expectAFalseLoopIsRefused(const std::filesystem::path& run_dir) {
  SystemConfig config;
  io::readConfigYaml(run_dir.parent_path() / "recording" / "rig.yaml", config);
  enum class Tamper { kDrop, kFalsify };
  bool tampered = false;
  const auto tamperFirstVerifiedLoop = [&](Tamper tamper) -> mapping::LoopVerifier {
    tampered = false;
    return [&, tamper](const mapping::PoseGraph& graph, const mapping::KeyframeStore& store,
                       std::size_t current, const mapping::LoopCandidate& candidate,
                       const MappingConfig& mapping_config, const OdometryConfig& odometry) {
      mapping::LoopAttempt attempt =
          mapping::verifyLoop(graph, store, current, candidate, mapping_config, odometry);
      if (!attempt.accepted || tampered) return attempt;
      tampered = true;
      if (tamper == Tamper::kDrop) {
        attempt.accepted = false;
        attempt.note = "dropped by the test";
      } else {
        attempt.loop.T_from_to =
            attempt.loop.T_from_to *
            lie::SE3(lie::SO3::fromRollPitchYaw(0.0, 0.0, 0.0524), Eigen::Vector3d(0.0, 1.5, 0.0));
      }
      return attempt;
    };
  };
  const MappingReplay dropped =
      replayMapping(run_dir, config, tamperFirstVerifiedLoop(Tamper::kDrop));
  ASSERT_TRUE(tampered);
  const MappingReplay guarded =
      replayMapping(run_dir, config, tamperFirstVerifiedLoop(Tamper::kFalsify));
  ASSERT_TRUE(tampered);
  EXPECT_TRUE(std::any_of(guarded.attempts.begin(), guarded.attempts.end(),
                          [](const mapping::LoopRecord& r) {
                            return r.attempt.note.find("inconsistent") != std::string::npos;
                          }))
      << "the false loop was not refused";
  std::string loops;  // what happened to every attempt, for a failure's message
  for (const mapping::LoopRecord& r : guarded.attempts)
    loops += fmt::format("t {:.1f} s: {} chi2 {:.1f} {}; ", r.t_s, r.attempt.accepted, r.chi2,
                         r.attempt.note);
  const double guarded_m = largestDifference_m(guarded.poses, dropped.poses);
  ::testing::Test::RecordProperty("false_loop_attempts", loops);
  ::testing::Test::RecordProperty("false_loop_map_change_m", std::to_string(guarded_m));
  EXPECT_LT(guarded_m, 0.001);

  config.mapping.loop_max_chi2 = 1e12;  // the consistency check off
  const MappingReplay unguarded_dropped =
      replayMapping(run_dir, config, tamperFirstVerifiedLoop(Tamper::kDrop));
  const MappingReplay unguarded =
      replayMapping(run_dir, config, tamperFirstVerifiedLoop(Tamper::kFalsify));
  ASSERT_TRUE(tampered);
  const double unguarded_m = largestDifference_m(unguarded.poses, unguarded_dropped.poses);
  ::testing::Test::RecordProperty("false_loop_unguarded_map_change_m", std::to_string(unguarded_m));
  EXPECT_GT(unguarded_m, 0.3);
}

void expectEveryScanUsed(const RunSummary& s) {
  EXPECT_GE(s.scans_processed + 7, s.scans);  // all but the scans before 0.5 s of IMU and the first
  EXPECT_LE(s.lidar_rejected, s.scans / 20);
  EXPECT_GT(s.keyframes, 5u);
  EXPECT_GT(s.map_points, 100000u);
}

// A rig with a 9-axis IMU module (orientation output, 0.7 deg tilt error): 15 s, 19 m. taiga
// keeps 0.6 cm APE and 0.10 % end-point drift here; before the initial attitude was taken at the
// first scan's start (it was the attitude 0.1-0.2 s later) this walk had 3.9 cm and 1.3 %.
TEST(OdometryScenario, HandheldWalkWithImuOrientationStaysWithinCentimetresAndRepeatsExactly) {
  test::TempDir dir;
  const ScenarioRun run = simulateAndRun("handheld-loop", 15.0, 3, dir.path());
  expectEveryScanUsed(run.summary);
  EXPECT_GT(run.summary.path_length_m, 10.0);
  EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.03);
  EXPECT_LT(run.evaluation.drift.drift_percent, 0.5);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "run_rig" / "map.las"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "run_rig" / "summary.json"));

  // The same recording again on one thread: the same trajectory, bit for bit.
  {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    SystemConfig config;
    io::readConfigYaml(dir.path() / "recording" / "rig.yaml", config);
    runOdometry(dir.path() / "recording" / "recording.bag", config,
                {.out_dir = dir.path() / "rerun", .show_progress = false});
  }
  EXPECT_EQ(readFile(dir.path() / "run_rig" / "trajectory.tum"),
            readFile(dir.path() / "rerun" / "trajectory.tum"));
  EXPECT_EQ(readFile(dir.path() / "run_rig" / "trajectory_imu.tum"),
            readFile(dir.path() / "rerun" / "trajectory_imu.tum"));
  // The map, exported from the keyframe store at the end of the run, too.
  EXPECT_EQ(readFile(dir.path() / "run_rig" / "map.las"),
            readFile(dir.path() / "rerun" / "map.las"));
  EXPECT_EQ(readFile(dir.path() / "run_rig" / "keyframes" / "poses.tum"),
            readFile(dir.path() / "rerun" / "keyframes" / "poses.tum"));
}

// A 6-axis IMU (the Ouster's own) that starts moving: the tilt from the mean specific force is
// 5.5 deg off, gravity alignment levels the world after 2 s, and the residual (about 1.4 deg at
// the start) decays as the local map renews itself. The end-point drift (first poses aligned)
// measures mostly that first-pose tilt: 7.7 cm APE and 2.5 % on this 15 s, 19 m walk. The
// documented best effort of issue 6, bounded so that a regression shows.
TEST(OdometryScenario, SixAxisImuStartingInMotionAndLidarOnlyStayWithinDecimetres) {
  test::TempDir dir;
  const ScenarioRun run = simulateAndRun("mixed", 15.0, 3, dir.path());
  expectEveryScanUsed(run.summary);
  EXPECT_GT(run.summary.path_length_m, 10.0);
  EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.12);
  EXPECT_LT(run.evaluation.drift.drift_percent, 3.5);

  // The same scans in a bag without the IMU, with odometry.imu_use left at auto: the run must
  // notice that no IMU reading comes and switch to lidar-only odometry (constant-velocity
  // prediction and deskew). 4.8 cm APE here, with a jittery path (4.5 cm RPE per scan against
  // 0.7 cm with the IMU): every scan is still registered, none rejected.
  SystemConfig config;
  io::readConfigYaml(dir.path() / "recording" / "rig.yaml", config);
  {
    io::Recording recording =
        io::openRecording(dir.path() / "recording" / "recording.bag", config.recording, config.rig);
    io::BagWriter scans_only(dir.path() / "scans_only.bag");
    while (std::optional<io::RecordingEvent> event = recording.next()) {
      if (const auto* scan = std::get_if<io::Scan>(&*event))
        scans_only.writeScan(config.recording.lidar_topic, "os_sensor", *scan);
    }
  }
  config.recording.imu_topic.clear();
  config.recording.gnss_topic.clear();
  ASSERT_EQ(config.odometry.imu_use, "auto");
  const RunSummary lidar_only =
      runOdometry(dir.path() / "scans_only.bag", config,
                  {.out_dir = dir.path() / "lidar_only", .show_progress = false});
  EXPECT_EQ(lidar_only.imu_samples, 0u);
  EXPECT_EQ(lidar_only.scans_processed, lidar_only.scans);
  EXPECT_EQ(lidar_only.lidar_rejected, 0u);
  const eval::EvalResult lidar_only_eval =
      eval::evaluate(io::readTum(dir.path() / "lidar_only" / "trajectory_odometry.tum"),
                     io::readTum(dir.path() / "recording" / "groundtruth.tum"), {});
  EXPECT_LT(lidar_only_eval.ape.translation_m.rmse, 0.10);
  RecordProperty("lidar_only_ape_rmse_m", std::to_string(lidar_only_eval.ape.translation_m.rmse));
}

// The three-minute walk of issues 6 and 7. The odometry alone (issue 6, no loop closure) must
// keep ATE <= 10 cm and end-point drift <= 0.5 % on this 207 m loop; a lidar factor whose
// heading sigma is tighter than its tilt sigma took it from 16 to about 6.6 cm. The mapping graph
// then closes the loop when the walker returns to the start: the end pose comes back to within
// 5 cm of the start's true relative position, and the ATE drops below 5 cm (issue 7): the
// 64-beam rig.yaml's 0.5 m NDT cells shrink the steps by 0.12 % instead of 0.21 % with 1 m cells
// (docs/odometry.md, "Scale").
TEST(OdometryScenario, HandheldLoopOfThreeMinutes) {
  test::TempDir dir;
  const ScenarioRun run = simulateAndRun("handheld-loop", 180.0, 2, dir.path());
  expectEveryScanUsed(run.summary);
  EXPECT_GT(run.summary.path_length_m, 150.0);
  EXPECT_LT(run.odometry_evaluation.drift.drift_percent, 0.5);
  EXPECT_LT(run.odometry_evaluation.ape.translation_m.rmse, 0.10);

  EXPECT_GE(run.summary.loop_closures, 1u);
  EXPECT_LT(run.evaluation.drift.drift_m, 0.05);
  EXPECT_LT(run.evaluation.ape.translation_m.rmse, run.odometry_evaluation.ape.translation_m.rmse);
  EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.05);  // issue 7's bound
  EXPECT_LT(run.map_sharpness.rms_m, 0.04);
  // The loop corrections reach the live odometry (mapping.correct_odometry): its published poses
  // follow the graph's, so its end comes back to the start as the graph's does (session 63: 3.5
  // cm end-point drift against the odometry's 8.8 cm), and where a loop bent the recent
  // keyframes the local map was rebuilt (3 times). A correction applied the wrong way would
  // double the odometry's end-point drift. The RMSE over the walk no longer tells them apart:
  // the loops close in the last 10 s of 180, and trajectory_odometry.tum is levelled at the end
  // by the frame's tilt as finally estimated, which the live poses did not know yet (session
  // 48: 6.52 live vs 6.64 cm; session 63, with an odometry of 1.8 cm: 1.85 vs 1.83 cm).
  EXPECT_GE(run.summary.local_map_rebuilds, 1u);
  EXPECT_LT(run.online_evaluation.drift.drift_m, 0.5 * run.odometry_evaluation.drift.drift_m);
  EXPECT_LT(run.online_evaluation.ape.translation_m.max,
            1.1 * run.odometry_evaluation.ape.translation_m.max);
  expectAFalseLoopIsRefused(dir.path() / "run_rig");
}

// Issue 6: no divergence and ATE <= 15 cm through vibration bursts and long stops. The crane's
// per-scan boxes (machine_boxes.csv) and the cabin box (rig.self_boxes_body) keep the machine's
// own returns out of registration.
TEST(OdometryScenario, HarvesterOfThreeMinutes) {
  test::TempDir dir;
  const ScenarioRun run = simulateAndRun("harvester", 180.0, 2, dir.path(), {.crop_machine = true});
  expectEveryScanUsed(run.summary);
  EXPECT_LE(run.summary.lidar_inflated, run.summary.scans / 20);
  EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.15);
  EXPECT_LT(run.evaluation.ape.translation_m.max, 0.30);
}

// Issue 18: the rig as its user would write it. With `typical` realism the recording has IMU
// noise 2x its datasheet, wandering biases, scale and axis errors, a 2 deg / 3 cm extrinsic
// error, a 10 ms time offset, noisier and lossier lidar returns and wind; rig.yaml states the
// nominal rig. Measured on these 15 s walks (64 beams): ATE 3.2, 3.5, 2.2 cm with rig.yaml (5.1,
// 3.1, 2.6 cm before the odometry estimated its frame's tilt, session 49; 5.9, 3.9, 3.8 cm before
// the levelling estimated the accelerometer bias, session 46), against
// 0.5-1.7 cm ideal; told the truth (rig_truth.yaml) the same recordings give 0.9-1.8 cm. So the
// estimator copes with the sensors' errors, and the rig's unstated extrinsics and time offset cost
// the rest (bench/realism_sources.sh measures each source on its own; the self-calibration issue is
// to remove it).
// The other registration methods on the same walk and rig. D2D was lost from the first scans once
// the local map's cells became 0.5 m: its source cells came from the 0.4 m voxel-filtered scan,
// one to three points each, below min_points_per_cell; they now come from the scan before the
// filter. Measured ATE: NDT 3.1, D2D 3.4, GICP 3.6 cm.
TEST(OdometryScenario, EveryRegistrationMethodTracksAHandheldWalk) {
  test::TempDir dir;
  const ScenarioRun ndt =
      simulateAndRun("handheld-loop", 15.0, 1, dir.path(), {.realism = "typical"});
  for (const std::string method : {"d2d", "gicp"}) {
    SCOPED_TRACE(method);
    const ScenarioRun run = simulateAndRun("handheld-loop", 15.0, 1, dir.path(),
                                           {.realism = "typical", .method = method});
    expectEveryScanUsed(run.summary);
    EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.10);
    EXPECT_LT(run.evaluation.ape.translation_m.rmse, 2.0 * ndt.evaluation.ape.translation_m.rmse);
  }
}

TEST(OdometryScenario, TypicalRealismWithTheRigAUserWouldWriteOnThreeSeeds) {
  for (const std::uint64_t seed : {1, 2, 3}) {
    SCOPED_TRACE(seed);
    test::TempDir dir;
    const ScenarioRun stated =
        simulateAndRun("handheld-loop", 15.0, seed, dir.path(), {.realism = "typical"});
    expectEveryScanUsed(stated.summary);
    EXPECT_LT(stated.evaluation.ape.translation_m.rmse, 0.10);
    EXPECT_LT(stated.evaluation.drift.drift_percent, 4.0);
    const ScenarioRun truth = simulateAndRun("handheld-loop", 15.0, seed, dir.path(),
                                             {.realism = "typical", .rig_file = "rig_truth.yaml"});
    expectEveryScanUsed(truth.summary);
    EXPECT_LT(truth.evaluation.ape.translation_m.rmse, 0.03);
    EXPECT_LT(truth.evaluation.ape.translation_m.rmse, stated.evaluation.ape.translation_m.rmse);
    // Issue 20: the same rig.yaml, calibrated on the recording first. The time offset is found
    // to within a millisecond (the truth: 10 ms at the start, drifting 10 ppm); the lever arm
    // stays 3 cm off, which keeps the run above the true rig's. Measured ATE 2.9, 1.7, 1.9 cm:
    // 0.91, 0.49, 0.86 of the stated rig's (0.68, 0.40, 0.67 before session 49: the stated rig
    // gained more from the frame's tilt estimate than the calibrated one).
    const ScenarioRun calibrated =
        simulateAndRun("handheld-loop", 15.0, seed, dir.path(),
                       {.realism = "typical", .calibrate_at_start = true});
    expectEveryScanUsed(calibrated.summary);
    ASSERT_TRUE(calibrated.summary.calibration);
    const CalibrationRunReport& c = *calibrated.summary.calibration;
    EXPECT_TRUE(c.skipped.empty()) << c.skipped;
    EXPECT_TRUE(c.offset_observable);
    EXPECT_NEAR(c.time_offset_s, 0.010, 0.001);
    EXPECT_EQ(c.rotation_observable_axes, "xyz");
    EXPECT_LT(calibrated.evaluation.ape.translation_m.rmse,
              0.95 * stated.evaluation.ape.translation_m.rmse);
    RecordProperty("ape_stated_calibrated_m_seed_" + std::to_string(seed),
                   std::to_string(stated.evaluation.ape.translation_m.rmse) + " " +
                       std::to_string(calibrated.evaluation.ape.translation_m.rmse));
    EXPECT_LT(calibrated.evaluation.ape.translation_m.rmse, 0.04);  // measured 3.3 cm on seed 1
  }
}

// A lidar clock that runs 200 ppm fast against the IMU's (18 ms over the 90 s; a free-running
// oscillator at 10 ppm gets there in 30 min), the offset stated right at the start, the rest
// ideal, 32 beams: the run follows the offset (calibration.track_offset,
// pipeline/clock_tracker.hpp) and says the drift.
TEST(OdometryScenario, ADriftingLidarClockIsFollowed) {
  test::TempDir dir;
  const RunSetup setup{.overrides = "rig: {lidar_clock_drift_ppm: 200}\n", .beams = 32};
  const ScenarioRun tracked = simulateAndRun("handheld-loop", 90.0, 4, dir.path(), setup);
  RunSetup untracked_setup = setup;
  untracked_setup.track_offset = false;
  const ScenarioRun untracked =
      simulateAndRun("handheld-loop", 90.0, 4, dir.path(), untracked_setup);
  expectEveryScanUsed(tracked.summary);
  ASSERT_TRUE(tracked.summary.clock);
  const ClockTrackingReport& clock = *tracked.summary.clock;
  EXPECT_GE(clock.windows.size(), 3u);
  EXPECT_EQ(clock.held, 0u);
  // The offset falls by the drift: -200 ppm x 90 s = -18 ms at the end.
  EXPECT_NEAR(clock.offset_last_s, -200e-6 * 90.0, 0.0015) << clock.text;
  ASSERT_TRUE(clock.drift_ppm);
  EXPECT_NEAR(*clock.drift_ppm, -200.0, std::max(20.0, 3.0 * *clock.drift_sigma_ppm)) << clock.text;
  EXPECT_FALSE(untracked.summary.clock);
  RecordProperty("odometry_ape_tracked_untracked_m",
                 std::to_string(tracked.odometry_evaluation.ape.translation_m.rmse) + " " +
                     std::to_string(untracked.odometry_evaluation.ape.translation_m.rmse));
  // Not asserted: what the drift costs. On this ideal 32-beam walk the untracked odometry was
  // 3.5 cm and the tracked 3.8 (an earlier version); on a `typical` 64-beam walk with 100 ppm,
  // 20.5 against 13.8 cm (bench/BENCHMARK.md, "Session 51").
}

// Deliberately wrong settings, the others ideal: the true IMU noise and bias walks 3x what
// rig.yaml says, its T_body_lidar 2 deg and 3 cm off, and a 10 ms lidar-IMU time offset it
// does not state. Measured: ATE 6.6, 4.4, 4.2 cm on these 15 s walks; no scan is lost.
TEST(OdometryScenario, DeliberatelyWrongSettingsOnThreeSeeds) {
  for (const std::uint64_t seed : {1, 2, 3}) {
    SCOPED_TRACE(seed);
    test::TempDir dir;
    const ScenarioRun run = simulateAndRun(
        "handheld-loop", 15.0, seed, dir.path(),
        {.overrides = "imu: {noise_density_factor: 3, bias_walk_factor: 3}\n"
                      "rig: {extrinsic_rotation_error_deg: 2, extrinsic_translation_error_m: "
                      "0.03, lidar_time_offset_s: 0.010}\n"});
    expectEveryScanUsed(run.summary);
    EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.11);
    EXPECT_LT(run.evaluation.drift.drift_percent, 4.0);
  }
}

// The harvester with `typical` realism and the rig a user would write: vibration through an
// IMU 2x noisier than its datasheet with scale errors and clipping at 4 g, the crane cropped.
TEST(OdometryScenario, HarvesterWithTypicalRealism) {
  test::TempDir dir;
  const ScenarioRun run = simulateAndRun("harvester", 90.0, 3, dir.path(),
                                         {.crop_machine = true, .realism = "typical"});
  expectEveryScanUsed(run.summary);
  EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.15);
  EXPECT_LT(run.evaluation.ape.translation_m.max, 0.30);
}

// Issue 19's recording as users have it: scans kept at 2 Hz, deskewed upstream without a time
// field, no IMU, the handheld walk's turns of up to 40 deg between kept scans and its roll and
// pitch sway; run with the rig.yaml a user would write plus only the documented switch
// recording.deskewed: true. Before the wide basin's correlative search (docs/odometry.md) both
// heads diverged: APE 2.7-10 m, lost or silently wrong. Measured now: 2.3 cm (HDL-32E, seed 1),
// 1.1 cm (64 of the OS0-128's beams, seed 2); bench/BENCHMARK.md has six seeds of each head.
TEST(OdometryScenario, LidarOnlyAtTwoHertzThroughFastTurnsStaysWithinDecimetres) {
  const std::string kept_at_2_hz =
      "output: {point_layout: deskewed, scan_stride: 5, imu: false, gnss: false}\n";
  struct Head {
    std::string lidar;
    int beams;
    std::uint64_t seed;
  };
  for (const Head& head :
       {Head{"lidar: {model: hdl-32e, columns: 2048}\n", 0, 1}, Head{"", 64, 2}}) {
    SCOPED_TRACE(head.lidar.empty() ? "OS0-128, 64 beams" : "HDL-32E");
    test::TempDir dir;
    const ScenarioRun run = simulateAndRun(
        "handheld-loop", 60.0, head.seed, dir.path() / std::to_string(head.seed),
        {.overrides = head.lidar + kept_at_2_hz,
         .beams = head.beams,
         .deskewed = RecordingConfig::Deskewed::kYes});
    EXPECT_EQ(run.summary.imu_samples, 0u);
    EXPECT_GT(run.summary.path_length_m, 70.0);
    EXPECT_EQ(run.summary.health.lost, 0u);
    EXPECT_FALSE(run.summary.health.trackLost());
    EXPECT_LT(run.odometry_evaluation.ape.translation_m.rmse, 0.10);
    EXPECT_LT(run.odometry_evaluation.ape.translation_m.max, 0.30);
  }
}

// Clouds without a time field, run with the rig.yaml a user would write (docs/recordings.md,
// "Per-point times, and clouds deskewed upstream"). Deskewed upstream, the default
// recording.deskewed: auto finds it by the sweeps' seams and takes every point at the stamp;
// `false` makes the times up from the azimuth and deskews the clouds a second time (before the
// check the default: 20-27 cm with health ok on 60 s walks, BENCHMARK.md "Session 49"), and the
// run counts those scans. A raw sweep written without its time field is found raw and deskewed
// with the made-up times. Measured (mixed, typical, 15 s, 32 beams, seed 1), odometry APE: found
// 3.7 cm, deskewed twice 6.2 cm, the raw sweep 3.3 cm.
TEST(OdometryScenario, CloudsWithoutPointTimesAreJudgedByTheirSeams) {
  using Deskewed = RecordingConfig::Deskewed;
  using Verdict = SweepCheck::Verdict;
  test::TempDir dir;
  auto run = [&](const std::string& layout, Deskewed deskewed, const std::string& name) {
    return simulateAndRun("mixed", 15.0, 1, dir.path() / name,
                          {.realism = "typical",
                           .overrides = "output: {point_layout: " + layout + "}\n",
                           .beams = 32,
                           .deskewed = deskewed});
  };
  const ScenarioRun found = run("deskewed", Deskewed::kAuto, "found");
  ASSERT_TRUE(found.summary.sweep_check);
  EXPECT_EQ(found.summary.sweep_check->verdict, Verdict::kDeskewedUpstream);
  EXPECT_EQ(found.summary.scans_with_made_up_times, 0u);
  const ScenarioRun twice = run("deskewed", Deskewed::kNo, "twice");
  EXPECT_FALSE(twice.summary.sweep_check);  // the configuration said
  EXPECT_EQ(twice.summary.scans_with_made_up_times, twice.summary.scans);
  const ScenarioRun raw = run("untimed", Deskewed::kAuto, "raw");
  ASSERT_TRUE(raw.summary.sweep_check);
  EXPECT_EQ(raw.summary.sweep_check->verdict, Verdict::kRawSweep);
  EXPECT_EQ(raw.summary.scans_with_made_up_times, raw.summary.scans);
  const double found_m = found.odometry_evaluation.ape.translation_m.rmse;
  EXPECT_LT(found_m, 0.05);
  EXPECT_LT(found_m, 0.8 * twice.odometry_evaluation.ape.translation_m.rmse);
  EXPECT_LT(raw.odometry_evaluation.ape.translation_m.rmse, 0.05);
}

// Issue 19: faults injected into a `harsh` handheld walk (docs/simulator.md, "Faults"), the run
// told the true rig (unless `setup` says otherwise), beside the same walk without the fault.
// Whatever the fault, no scan the run calls ok is 1 m off, and its ATE stays within 5 cm of the
// fault-free run's; what the run says of each fault is checked in its own test.
struct FaultOutcome {
  ScenarioRun clean, faulty;
  std::vector<eval::StatusApe> by_status;  ///< the faulty run's APE per scan status
};

FaultOutcome runWithFault(const std::string& faults, std::uint64_t seed = 3,
                          RunSetup setup = {.realism = "harsh", .rig_file = "rig_truth.yaml"}) {
  test::TempDir dir;  // one per test: the two runs in subdirectories
  FaultOutcome o;
  o.clean = simulateAndRun("handheld-loop", 20.0, seed, dir.path() / "clean", setup);
  setup.overrides = "faults: {" + faults + "}\n";
  o.faulty = simulateAndRun("handheld-loop", 20.0, seed, dir.path() / "faulty", setup);
  o.by_status = eval::apeByStatus(
      o.faulty.evaluation,
      eval::readScanStatuses(dir.path() / "faulty" /
                             ("run_" + std::filesystem::path(setup.rig_file).stem().string()) /
                             "scans.csv"));
  return o;
}

void expectNeverSilentlyWrong(const FaultOutcome& o) {
  for (const eval::StatusApe& s : o.by_status) {
    if (s.status == "ok") {
      EXPECT_LT(s.max_m, 1.0) << s.poses << " ok poses";
    }
  }
  EXPECT_LT(o.faulty.evaluation.ape.translation_m.rmse,
            o.clean.evaluation.ape.translation_m.rmse + 0.05);
}

bool saysSomewhere(const HealthReport& h, const std::string& words) {
  return std::any_of(h.stretches.begin(), h.stretches.end(), [&](const HealthStretch& s) {
    return s.reason.find(words) != std::string::npos;
  });
}

// No IMU readings for 1 s: it crashed the run before (a non-finite smoother). Now the scans in
// the gap are predicted at constant velocity, registered coarse to fine and degraded, and the run
// goes on on its map. With the fine cells alone, seed 4 diverged by 40 m (ATE; 2 of seeds 1-8).
TEST(OdometryScenario, AnImuGapOfOneSecondIsBridgedAndSaid) {
  for (const std::uint64_t seed : {3, 4}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const FaultOutcome o = runWithFault("imu_gap_start_s: 8, imu_gap_s: 1", seed);
    expectNeverSilentlyWrong(o);
    const HealthReport& h = o.faulty.summary.health;
    EXPECT_FALSE(h.trackLost());
    EXPECT_NE(h.verdict(), "ok");
    EXPECT_TRUE(saysSomewhere(h, "no IMU readings")) << h.verdict();
  }
}

// The same gap on a `typical` walk with the rig its user would write. The IMU factors across the
// gap held the last reading, whose gravity the sway then turned by degrees: the velocity was
// pulled by up to 2 m/s and the poses 0.4 m from their registrations. Measured here: ok scans up
// to 38.6 cm off (degraded 31.1, lost 28.6 cm), ATE 6.7 cm against 4.8 cm without the gap. They
// are now the twist's constant-velocity increments: at most 10.7 / 12.2 / 8.2 cm, ATE 4.5 cm
// (docs/odometry.md, Health).
TEST(OdometryScenario, AnImuGapOnAUsersRigKeepsThePosesOnTheirRegistrations) {
  const FaultOutcome o =
      runWithFault("imu_gap_start_s: 8, imu_gap_s: 1", 31, {.realism = "typical"});
  for (const eval::StatusApe& s : o.by_status) {
    SCOPED_TRACE(s.status);
    EXPECT_LT(s.max_m, 0.15);
  }
  EXPECT_LT(o.faulty.evaluation.ape.translation_m.rmse,
            o.clean.evaluation.ape.translation_m.rmse + 0.015);
}

// 3 s of open field on a `harsh` walk with the rig its user would write: the lidar sees the
// ground alone, the track is lost, and the local map starts over. The odometry now starts over
// with it (attitude from the last second's readings, velocity from the next two scans) instead
// of going on from the state the loss left: ATE 13.5 -> 7.5 cm, the worst ok scan 25 -> 16 cm, a
// second map segment that re-attaches either way. With the same walk simulated with one ray per
// beam the run had ended lost (exit 3); on a 2 s IMU gap (seed 35, the calibration's gyro noise
// not applied) the new segment had diverged by 70 m with its scans called ok.
TEST(OdometryScenario, AnOpenFieldWhileWalkingLosesTheTrackAndFindsItAgain) {
  test::TempDir dir;
  const ScenarioRun run = simulateAndRun(
      "handheld-loop", 20.0, 31, dir.path(),
      {.realism = "harsh", .overrides = "faults: {open_field_start_s: 6, open_field_s: 3}\n"});
  const HealthReport& h = run.summary.health;
  const std::vector<eval::StatusApe> by_status = eval::apeByStatus(
      run.evaluation, eval::readScanStatuses(dir.path() / "run_rig" / "scans.csv"));
  for (const eval::StatusApe& s : by_status) {
    if (s.status == "ok") {
      EXPECT_LT(s.max_m, 0.2);
    }
  }
  EXPECT_FALSE(h.trackLost()) << h.verdict();
  EXPECT_GT(h.lost, 0u);
  EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.10);
}

// 20 scans that lost 90 % of their packets: the IMU carries the state, the run says it saw 20
// sparse scans, and goes on on the same map.
TEST(OdometryScenario, TwentyScansWithoutMostOfTheirPacketsAreSaidAndBridged) {
  const FaultOutcome o = runWithFault("packet_burst_start_s: 8, packet_burst_scans: 20");
  expectNeverSilentlyWrong(o);
  const HealthReport& h = o.faulty.summary.health;
  EXPECT_FALSE(h.trackLost());
  // The 20 scans are reported as sparse (lost packets), and none other.
  EXPECT_EQ(h.sparse_scans, 20u);
  ASSERT_EQ(h.sparse.size(), 1u);
  EXPECT_NEAR(h.sparse.front().from_s - sim::kRecordingEpoch_s, 8.1, 0.15);  // the first scan end
}

// A scan from 8 s earlier (another place) stamped now: not ok, and the walk goes on.
TEST(OdometryScenario, AScanFromAnotherPlaceIsFlagged) {
  const FaultOutcome o = runWithFault("splice_at_s: 10, splice_from_s: 2");
  expectNeverSilentlyWrong(o);
  const HealthReport& h = o.faulty.summary.health;
  EXPECT_GE(h.degraded + h.lost, 1u);
  EXPECT_FALSE(h.trackLost());
}

// The first stretch of at least `min_s` in which the truth moves slower than 0.2 m/s (the walker
// stands; the rig in the hand still sways at about 0.1 m/s), as [from, to) in motion time.
std::pair<double, double> firstStandStill_s(const Trajectory& truth, double min_s) {
  const std::vector<StampedPose>& p = truth.poses();
  std::size_t from = 0;
  for (std::size_t i = 1; i < p.size(); ++i) {
    const double speed_mps =
        (p[i].pose.translation() - p[i - 1].pose.translation()).norm() / (p[i].t_s - p[i - 1].t_s);
    if (speed_mps >= 0.2) {
      from = i;
    } else if (p[i].t_s - p[from].t_s >= min_s) {
      return {p[from].t_s - sim::kRecordingEpoch_s, p[i].t_s - sim::kRecordingEpoch_s};
    }
  }
  return {0.0, 0.0};
}

// A 2 s stand-still in an open field: the walker stops (a pause forced into the first 15 s), and
// while it stands the lidar sees only the ground (a fifth of its points), which constrains
// height, roll and pitch well and the position and heading only through the terrain's relief.
// Measured: the registrations stay ok (Hessian condition 530-880 against 120-145 in the forest,
// below degenerate_condition), nothing drifts, and the run reports the 20 scans as sparse; the
// walk goes on on the same map.
TEST(OdometryScenario, ATwoSecondStandStillInAnOpenFieldIsBridgedAndSaid) {
  test::TempDir dir;
  const std::string pause = "motion: {pause_interval_s: 10, pause_min_s: 2.5, pause_max_s: 2.5}\n";
  RunSetup setup{.realism = "harsh", .overrides = pause, .rig_file = "rig_truth.yaml"};
  FaultOutcome o;
  o.clean = simulateAndRun("handheld-loop", 20.0, 3, dir.path() / "clean", setup);
  const auto [still_from_s, still_to_s] =
      firstStandStill_s(io::readTum(dir.path() / "clean" / "recording" / "groundtruth.tum"), 2.0);
  ASSERT_GT(still_from_s, 2.0) << "no stand-still of 2 s in the walk";
  setup.overrides +=
      fmt::format("faults: {{open_field_start_s: {}, open_field_s: 2}}\n", still_from_s + 0.1);
  o.faulty = simulateAndRun("handheld-loop", 20.0, 3, dir.path() / "faulty", setup);
  o.by_status = eval::apeByStatus(
      o.faulty.evaluation,
      eval::readScanStatuses(dir.path() / "faulty" / "run_rig_truth" / "scans.csv"));
  expectNeverSilentlyWrong(o);
  const HealthReport& h = o.faulty.summary.health;
  EXPECT_FALSE(h.trackLost());
  EXPECT_GE(h.sparse_scans, 18u);  // 2 s at 10 Hz
  EXPECT_EQ(h.sparse.size(), 1u);
  RecordProperty("stand_still_s", fmt::format("{:.1f}..{:.1f}", still_from_s, still_to_s));
}

// The poses of the scans the run called ok, evaluated alone (aligned on themselves): the map
// where the run says it is on track, whatever the flagged scans did.
eval::EvalResult evaluateOkScans(const std::filesystem::path& run_dir, const Trajectory& truth) {
  return eval::evaluate(eval::posesWithStatus(io::readTum(run_dir / "trajectory.tum"),
                                              eval::readScanStatuses(run_dir / "scans.csv"), "ok"),
                        truth, {});
}

// The lidar blind for 10 s (every packet lost: no scans at all) in a `harsh` handheld walk.
// With the IMU its dead reckoning drifts about a metre, and the first scans after the gap are
// searched for (the wide basin: after 1 s without an ok scan) and accepted (the jump test grows
// with that time): the walk goes on on the same map. Before, the fixed jump bound rejected them
// until the local map was given up. Without an IMU the constant velocity is metres and 30 deg
// off: lost, a new map segment, which the mapping graph finds in the map and ties to it
// (relocalization). Either way the run recovered, its ok scans as accurate as the walk's without
// the fault. Since session 49 (the odometry estimates its frame's tilt) the IMU's dead reckoning
// through these 10 s ends too far off for the wide basin too, on this harsh walk: lost, a new
// map segment, re-attached like the lidar-only run (recovered), its ok scans as accurate. Since
// session 54 (stem cells) the lidar-only dead reckoning ends 24 m and 118 deg off, beyond the
// relocalization's window: only the stem constellation finds the segment in the map.
TEST(OdometryScenario, ATenSecondBlindStretchIsReattachedWithAndWithoutAnImu) {
  test::TempDir dir;
  const std::string blind =
      "faults: {packet_burst_start_s: 8, packet_burst_scans: 100, packet_burst_loss: 1.0}\n";
  for (const bool lidar_only : {false, true}) {
    SCOPED_TRACE(lidar_only ? "lidar only" : "with the IMU");
    RunSetup setup{.realism = "harsh", .rig_file = "rig_truth.yaml", .lidar_only = lidar_only};
    simulateAndRun("handheld-loop", 30.0, 3, dir.path() / "clean", setup);
    const Trajectory truth = io::readTum(dir.path() / "clean" / "recording" / "groundtruth.tum");
    const std::string run_name = lidar_only ? "run_rig_truth_lidar_only" : "run_rig_truth";
    const double clean_ok_m =
        evaluateOkScans(dir.path() / "clean" / run_name, truth).ape.translation_m.rmse;
    setup.overrides = blind;
    const ScenarioRun run = simulateAndRun("handheld-loop", 30.0, 3, dir.path() / "blind", setup);
    const HealthReport& h = run.summary.health;
    EXPECT_FALSE(h.trackLost()) << h.verdict();
    EXPECT_EQ(h.verdict(), "recovered");
    EXPECT_EQ(h.map_segments, 2u);
    EXPECT_EQ(h.reattached.size(), h.map_segments - 1);
    const eval::EvalResult ok = evaluateOkScans(dir.path() / "blind" / run_name, truth);
    EXPECT_LT(ok.ape.translation_m.rmse, clean_ok_m + 0.05);
    EXPECT_LT(ok.ape.translation_m.max, 0.3);
    RecordProperty(lidar_only ? "lidar_only_ok_ape_rmse_m" : "imu_ok_ape_rmse_m",
                   std::to_string(ok.ape.translation_m.rmse));
    RecordProperty(lidar_only ? "lidar_only_clean_ok_ape_rmse_m" : "imu_clean_ok_ape_rmse_m",
                   std::to_string(clean_ok_m));
  }
}

}  // namespace
}  // namespace taiga::pipeline
