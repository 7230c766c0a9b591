// A short simulated recording, read back as a user's recording would be.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

TEST(Simulate, WritesARecordingThatReadsBack) {
  test::TempDir dir;
  Scenario scenario = scenarioByName("mixed");  // the full OS0-128 1024 x 10
  const Simulation simulation(scenario, 1.5, 1);
  const SimulationSummary summary = writeSimulation(simulation, dir.path());
  EXPECT_EQ(summary.scans, 15u);

  SystemConfig config;
  io::readConfigYaml(dir.path() / "rig.yaml", config);  // valid keys and values only
  EXPECT_LT(
      (config.rig.T_body_lidar.translation() - simulation.lidar().T_body_lidar().translation())
          .norm(),
      1e-9);
  EXPECT_EQ(config.recording.lidar_topic, kLidarTopic);
  EXPECT_DOUBLE_EQ(config.odometry.imu.gyro_noise_density, scenario.imu.gyro_noise_density);

  io::Recording recording =
      io::openRecording(dir.path() / "recording.bag", config.recording, config.rig);
  std::size_t scans = 0, imu = 0, gnss = 0;
  double first_imu = 0.0, last_imu = 0.0, accel_norm_sum = 0.0;
  while (auto event = recording.next()) {
    if (const auto* scan = std::get_if<io::Scan>(&*event)) {
      const std::size_t n = scan->cloud_in_lidar.size();
      EXPECT_GT(n, 40000u) << "scan " << scan->index;  // of 131072 beams
      EXPECT_LT(n, 128000u) << "scan " << scan->index;
      EXPECT_NEAR(scan->t_end_s - scan->t_start_s, 0.1, 0.002);
      ++scans;
    } else if (const auto* sample = std::get_if<ImuSample>(&*event)) {
      if (imu == 0) first_imu = sample->t_s;
      last_imu = sample->t_s;
      accel_norm_sum += sample->acceleration_imu_mps2.norm();  // gait: +-3 m/s^2 about gravity
      EXPECT_FALSE(sample->orientation.has_value());  // mixed: the Ouster's 6-axis IMU
      ++imu;
    } else {
      ++gnss;
    }
  }
  EXPECT_EQ(scans, 15u);
  EXPECT_NEAR((imu - 1) / (last_imu - first_imu), 200.0, 0.5);
  EXPECT_NEAR(first_imu, kRecordingEpoch_s, 1e-6);
  EXPECT_NEAR(accel_norm_sum / imu, 9.81, 0.4);
  EXPECT_LE(gnss, 2u);  // 1 Hz, minus outages under the canopy
  EXPECT_EQ(summary.imu_samples, imu);

  const Trajectory truth = io::readTum(dir.path() / "groundtruth.tum");
  EXPECT_EQ(truth.size(), imu);
  EXPECT_LT((truth.poseAt(kRecordingEpoch_s + 0.7).translation() -
             simulation.motion().at(0.7).T_world_body.translation())
                .norm(),
            1e-3);

  std::ifstream in(dir.path() / "scene.json");
  const nlohmann::json scene = nlohmann::json::parse(in);
  EXPECT_EQ(scene["scenario"], "mixed");
  EXPECT_EQ(scene["trees"].size(), simulation.scene().trees().size());
  EXPECT_DOUBLE_EQ(scene["trees"][0]["dbh_m"].get<double>(), simulation.scene().trees()[0].dbh_m);
  EXPECT_DOUBLE_EQ(scene["world_frame"]["origin_latitude_deg"].get<double>(), 61.0);
}

TEST(Simulate, UnknownScenarioNamesTheChoices) {
  try {
    scenarioByName("jungle");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("--scenario jungle: unknown scenario; expected one of mixed"),
        std::string::npos);
  }
}

}  // namespace
}  // namespace taiga::sim
