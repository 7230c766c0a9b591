// The whole odometry on a simulated forest walk that starts while moving, against the
// simulator's ground truth. On this 15 s, 19 m walk taiga keeps 4.7 cm APE and 1.5 % end-point
// drift, most of it from the first seconds, while the tilt found by gravity alignment (1.3 deg off)
// converges; the thesis' 0.2-0.9 % is over 100-280 m. A broken deskew, gravity alignment,
// registration or IMU factor fails these bounds by a wide margin.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "../support/temp_dir.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/eval/evaluate.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/pipeline/run.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::pipeline {
namespace {

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct ScenarioRun {
  RunSummary summary;
  eval::EvalResult evaluation;
};

ScenarioRun simulateAndRun(const std::string& scenario_name, double duration_s, std::uint64_t seed,
                           const std::filesystem::path& dir) {
  sim::Scenario scenario = sim::scenarioByName(scenario_name);
  scenario.lidar.beams = 64;  // half the rays of an OS0-128: the same geometry, a faster test
  const sim::Simulation simulation(scenario, duration_s, seed);
  sim::writeSimulation(simulation, dir / "recording");

  SystemConfig config;
  io::readConfigYaml(dir / "recording" / "rig.yaml", config);
  validateAll(config);
  ScenarioRun run;
  run.summary = runOdometry(dir / "recording" / "recording.bag", config,
                            {.out_dir = dir / "run", .show_progress = false});
  run.evaluation = eval::evaluate(io::readTum(dir / "run" / "trajectory.tum"),
                                  io::readTum(dir / "recording" / "groundtruth.tum"), {});
  return run;
}

TEST(OdometryScenario, MixedForestWalkStaysWithinCentimetresAndRepeatsExactly) {
  test::TempDir dir;
  const ScenarioRun run = simulateAndRun("mixed", 15.0, 3, dir.path());
  const RunSummary& s = run.summary;
  EXPECT_GE(s.scans_processed + 7, s.scans);  // all but the scans before 0.5 s of IMU and the first
  EXPECT_LE(s.lidar_rejected, s.scans / 20);
  EXPECT_GT(s.keyframes, 5u);
  EXPECT_GT(s.map_points, 100000u);
  EXPECT_GT(s.path_length_m, 10.0);
  EXPECT_LT(run.evaluation.ape.translation_m.rmse, 0.10);
  EXPECT_LT(run.evaluation.drift.drift_percent, 2.0);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "run" / "map.las"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "run" / "summary.json"));
  RecordProperty("ape_rmse_m", std::to_string(run.evaluation.ape.translation_m.rmse));

  // The same recording again on one thread: the same trajectory, bit for bit.
  {
    const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    SystemConfig config;
    io::readConfigYaml(dir.path() / "recording" / "rig.yaml", config);
    runOdometry(dir.path() / "recording" / "recording.bag", config,
                {.out_dir = dir.path() / "rerun", .show_progress = false});
  }
  EXPECT_EQ(readFile(dir.path() / "run" / "trajectory.tum"),
            readFile(dir.path() / "rerun" / "trajectory.tum"));
  EXPECT_EQ(readFile(dir.path() / "run" / "trajectory_imu.tum"),
            readFile(dir.path() / "rerun" / "trajectory_imu.tum"));
  RecordProperty("drift_percent", std::to_string(run.evaluation.drift.drift_percent));
}

}  // namespace
}  // namespace taiga::pipeline
