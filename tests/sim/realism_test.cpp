// The realism presets: `ideal` is today's simulator bit for bit; `typical` and `harsh` put the
// errors the rig.yaml does not state into the recording, and the truth into rig_truth.yaml.
#include "taiga/sim/realism.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>

#include <cmath>
#include <set>

#include "../support/md5.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/sim/imu.hpp"
#include "taiga/sim/scenario_yaml.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

Scenario small(const std::string& name, const std::string& realism) {
  Scenario s = scenarioByName(name);
  applyRealism(realism, s);
  s.lidar.beams = 32;
  s.lidar.columns = 512;
  return s;
}

TEST(Realism, IdealChangesNothing) {
  for (const std::string& name : scenarioNames()) {
    Scenario s = scenarioByName(name);
    const std::string before = scenarioYaml(s);
    applyRealism("ideal", s);
    EXPECT_EQ(scenarioYaml(s), before) << name;
  }
  Scenario s;
  EXPECT_THROW(applyRealism("realistic", s), InputError);
}

// The bytes of d4e52ad (before the realism presets) for these short recordings, with the beam
// table it read from the Ouster metadata file: the ideal preset still writes exactly them.
// (trees.csv since gained the columns x_bh_m, y_bh_m: the hashes are of the new file.)
// The bag's bytes depend on the machine: on session 50's (AMD EPYC, AVX2) the unchanged code of
// 4073a25 writes the second hash, with the same ground truth and trees.csv (the lidar or IMU
// samples differ; cause not found), so either machine's hash is accepted.
TEST(Realism, IdealReproducesThePreviousRecordingsBitForBit) {
  struct Case {
    const char* scenario;
    std::array<const char*, 2> bag_md5;
    const char* groundtruth_md5;
    const char* trees_md5;
  };
  const Case cases[] = {
      {"mixed",
       {"d967764f99299acd1493df4b9328b000", "ce75e52cfb7e6e62706da148d2d98929"},
       "d5ff74722d6285206d55d788d3c9d6cf",
       "ac432d9af93686f3103c530eb4d6a43a"},
      {"harvester",
       {"f6e9a58adfc4f48e3fc0aa9389c16fb0", "12b2d6ae657037a09127e117d12376c2"},
       "560fc201946e1dd3a881722ba94493b9",
       "ce8847ea5793554ba2fcae6315359b80"},
  };
  for (const Case& c : cases) {
    test::TempDir dir;
    Scenario s = small(c.scenario, "ideal");
    s.lidar.metadata_json = "../shared/data/ouster/OS-0-128-U1_v2.3.0_1024x10.json";
    writeSimulation(Simulation(s, 1.5, 3), dir.path());
    EXPECT_THAT(c.bag_md5, ::testing::Contains(test::md5OfFile(dir.file("recording.bag"))))
        << c.scenario;
    EXPECT_EQ(test::md5OfFile(dir.file("groundtruth.tum")), c.groundtruth_md5) << c.scenario;
    EXPECT_EQ(test::md5OfFile(dir.file("trees.csv")), c.trees_md5) << c.scenario;
  }
}

SystemConfig readRig(const std::filesystem::path& path) {
  SystemConfig config;
  io::readConfigYaml(path, config);
  return config;
}

TEST(Realism, RigYamlStatesTheNominalRigAndRigTruthTheTrueOne) {
  test::TempDir dir;
  const Scenario s = small("mixed", "typical");
  const Simulation simulation(s, 1.5, 2);
  writeSimulation(simulation, dir.path());
  const SystemConfig stated = readRig(dir.file("rig.yaml"));
  const SystemConfig truth = readRig(dir.file("rig_truth.yaml"));
  const lie::SE3 error = stated.rig.T_body_lidar.inverse() * truth.rig.T_body_lidar;
  EXPECT_NEAR(error.rotation().Log().norm() * kDegPerRad, 2.0, 1e-6);
  EXPECT_NEAR(error.translation().norm(), 0.03, 1e-6);
  EXPECT_LT((truth.rig.T_body_lidar.translation() - simulation.lidar().T_body_lidar().translation())
                .norm(),
            1e-9);
  EXPECT_EQ(stated.rig.lidar_time_offset_s, 0.0);
  EXPECT_DOUBLE_EQ(truth.rig.lidar_time_offset_s, 0.010);
  EXPECT_DOUBLE_EQ(stated.odometry.imu.accel_noise_density, s.imu.accel_noise_density);
  EXPECT_DOUBLE_EQ(truth.odometry.imu.accel_noise_density, 2.0 * s.imu.accel_noise_density);
  EXPECT_DOUBLE_EQ(truth.odometry.imu.gyro_bias_random_walk, 2.0 * s.imu.gyro_bias_random_walk);
  // The gyro's drawn scale and axis errors are a key of the true rig; the user's rig has none.
  EXPECT_TRUE(stated.rig.gyro_axes.isIdentity());
  const Eigen::Matrix3d M_gyro = ImuSimulator(s.imu, simulation.seed()).gyroAxes();
  EXPECT_GT((M_gyro - Eigen::Matrix3d::Identity()).norm(), 1e-3);  // 0.5 %, 0.3 deg (1-sigma)
  EXPECT_TRUE(truth.rig.gyro_axes.M_reading_true.isApprox(M_gyro, 1e-12));

  // The lidar stamps are late on the IMU clock by the offset, plus the clock's drift: with the
  // truth's rig.lidar_time_offset_s the scans start at k * 0.1 s of motion time again.
  io::Recording recording =
      io::openRecording(dir.file("recording.bag"), truth.recording, truth.rig);
  std::size_t k = 0;
  while (auto event = recording.next()) {
    const auto* scan = std::get_if<io::Scan>(&*event);
    if (!scan) continue;
    const double t_motion = 0.1 * static_cast<double>(k++);
    EXPECT_NEAR(scan->t_start_s - kRecordingEpoch_s, t_motion + 10e-6 * t_motion, 1e-6);
  }
  EXPECT_EQ(k, 15u);
}

/// Measured minus exact IMU samples of the first `n` samples of a recording.
struct ImuErrors {
  std::vector<Eigen::Vector3d> accel_mps2, gyro_radps;
  std::vector<double> stamp_s;
};
ImuErrors imuErrors(const Scenario& s, std::size_t n) {
  const Simulation simulation(s, 2.0, 9);
  ImuParams exact_params = s.imu;
  exact_params.noise = false;
  ImuSimulator measured(s.imu, 9), exact(exact_params, 9);
  ImuErrors e;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = measured.nextTime_s();
    const ImuSample a = measured.next(simulation.motion()), b = exact.next(simulation.motion());
    e.accel_mps2.push_back(a.acceleration_imu_mps2 - b.acceleration_imu_mps2);
    e.gyro_radps.push_back(a.angular_velocity_imu_radps - b.angular_velocity_imu_radps);
    e.stamp_s.push_back(a.t_s - t);
  }
  return e;
}

/// Standard deviation of the first component's sample-to-sample differences / sqrt(2): the white
/// noise, free of the slowly varying biases and scale errors.
double whiteSigma(const std::vector<Eigen::Vector3d>& v) {
  double sum = 0.0;
  for (std::size_t i = 1; i < v.size(); ++i) sum += std::pow(v[i].x() - v[i - 1].x(), 2);
  return std::sqrt(sum / static_cast<double>(v.size() - 1) / 2.0);
}

TEST(Realism, ImuNoiseIsTheStatedTimesTheFactorAndClipsAtItsRange) {
  Scenario ideal = small("mixed", "ideal"), typical = small("mixed", "typical");
  const ImuErrors a = imuErrors(ideal, 400), b = imuErrors(typical, 400);
  const double stated_sigma = ideal.imu.accel_noise_density * std::sqrt(ideal.imu.rate_hz);
  EXPECT_NEAR(whiteSigma(a.accel_mps2) / stated_sigma, 1.0, 0.12);
  EXPECT_NEAR(whiteSigma(b.accel_mps2) / stated_sigma, 2.0, 0.25);
  // Jitter: the ideal stamps are exact, the typical ones scatter by about 0.2 ms.
  double jitter2 = 0.0;
  for (std::size_t k = 0; k < a.stamp_s.size(); ++k) {
    EXPECT_NEAR(a.stamp_s[k], 0.0, 1e-9);
    jitter2 += b.stamp_s[k] * b.stamp_s[k];
  }
  EXPECT_NEAR(std::sqrt(jitter2 / b.stamp_s.size()), 2e-4, 4e-5);

  Scenario clipped = typical;
  clipped.imu.accel_range_g = 0.5;  // below gravity: every sample clips
  clipped.imu.gyro_range_deg_s = 1.0;
  const Simulation simulation(clipped, 2.0, 9);
  ImuSimulator imu(clipped.imu, 9);
  for (int k = 0; k < 200; ++k) {
    const ImuSample sample = imu.next(simulation.motion());
    EXPECT_LE(sample.acceleration_imu_mps2.cwiseAbs().maxCoeff(), 0.5 * 9.81 + 1e-12);
    EXPECT_LE(sample.angular_velocity_imu_radps.cwiseAbs().maxCoeff(), kRadPerDeg + 1e-12);
  }
}

TEST(Realism, LostPacketsRemoveWholeBlocksOfSixteenColumns) {
  Scenario s = small("mixed", "typical");
  s.lidar.packet_loss_probability = 0.5;
  const Simulation simulation(s, 1.0, 4);
  const io::Scan scan =
      simulation.lidar().simulateScan(simulation.scene(), simulation.motion(), 3, 0.3);
  std::set<int> packets;
  for (const std::uint16_t col : scan.cloud_in_lidar.columns) packets.insert(col / 16);
  EXPECT_GT(packets.size(), 6u);  // of 32 packets, about half are lost
  EXPECT_LT(packets.size(), 26u);
}

TEST(Realism, WindMovesCrownsAndStemsButNotTheGround) {
  ForestParams forest;
  EXPECT_TRUE(Wind(forest, 1).calm());
  forest.wind_sway_m = 0.1;
  const Wind wind(forest, 1);
  EXPECT_FALSE(wind.calm());
  EXPECT_EQ(Wind::gain(Material::kGround, 30.0), 0.0);
  EXPECT_EQ(Wind::gain(Material::kRock, 30.0), 0.0);
  EXPECT_EQ(Wind::gain(Material::kBark, 1.5), 0.0);  // below 2 m nothing sways
  EXPECT_DOUBLE_EQ(Wind::gain(Material::kBark, 20.0), 1.0);
  EXPECT_DOUBLE_EQ(Wind::gain(Material::kFoliage, 11.0), 1.0);
  double largest = 0.0, sum = 0.0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d d = wind.displacement_m(Eigen::Vector3d(3.0, -7.0, 12.0), 0.05 * i);
    EXPECT_EQ(d.z(), 0.0);
    largest = std::max(largest, d.norm());
    sum += d.norm();
  }
  EXPECT_LE(largest, 0.1 * 1.31);
  EXPECT_GT(sum / 400, 0.1 * 0.3);  // it does move
}

}  // namespace
}  // namespace taiga::sim
