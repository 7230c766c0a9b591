// The truth files of a simulated recording: trees.csv, georef_truth.yaml (checked against the GNSS
// fixes in the bag through the geo module) and scenario.yaml (which reproduces the run).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/sim/scenario_yaml.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

/// A handheld walk with a small lidar head: the truth files, not the scans, are under test.
Scenario smallScenario(const std::string& extra_yaml = "") {
  Scenario scenario = scenarioByName("handheld-loop");
  applyScenarioOverridesText("lidar: {beams: 16, columns: 512, sub_rays: 1}\n" + extra_yaml,
                             "test overrides", scenario);
  return scenario;
}

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::vector<std::string>> readCsv(const std::filesystem::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream cells_in(line);
    for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

std::vector<GnssFix> gnssFixes(const std::filesystem::path& dir) {
  SystemConfig config;
  io::readConfigYaml(dir / "rig.yaml", config);
  io::Recording recording = io::openRecording(dir / "recording.bag", config.recording, config.rig);
  std::vector<GnssFix> fixes;
  while (auto event = recording.next()) {
    if (const auto* fix = std::get_if<GnssFix>(&*event)) fixes.push_back(*fix);
  }
  return fixes;
}

TEST(TruthOutputs, TreesCsvHoldsEveryStemAtFullPrecision) {
  test::TempDir dir;
  const Simulation simulation(smallScenario(), 0.5, 2);
  writeSimulation(simulation, dir.path());
  const auto rows = readCsv(dir.file("trees.csv"));
  ASSERT_EQ(rows.size(), simulation.scene().trees().size() + 1);
  EXPECT_EQ(rows[0],
            (std::vector<std::string>{"id", "x_m", "y_m", "z_m", "dbh_m", "height_m", "lean_deg",
                                      "lean_azimuth_deg", "species", "x_bh_m", "y_bh_m"}));
  for (std::size_t i = 0; i < simulation.scene().trees().size(); ++i) {
    const Tree& tree = simulation.scene().trees()[i];
    const auto& row = rows[i + 1];
    ASSERT_EQ(row.size(), 11u);
    EXPECT_EQ(std::stoul(row[0]), i);
    EXPECT_EQ(std::stod(row[1]), tree.base_world.x());
    EXPECT_EQ(std::stod(row[2]), tree.base_world.y());
    EXPECT_EQ(std::stod(row[3]), tree.base_world.z());
    EXPECT_EQ(std::stod(row[4]), tree.dbh_m);
    EXPECT_EQ(std::stod(row[5]), tree.height_m);
    EXPECT_NEAR(std::stod(row[6]), tree.lean_rad * kDegPerRad, 1e-12);
    EXPECT_TRUE(row[8] == "pine" || row[8] == "spruce" || row[8] == "birch") << row[8];
    EXPECT_EQ(std::stod(row[9]), tree.axisAt(1.3).x());
    EXPECT_EQ(std::stod(row[10]), tree.axisAt(1.3).y());
  }
}

/// GNSS fixes projected with the geo module and mapped through T_epsg_world^-1, against the true
/// world positions of the antenna (body origin) at the fix times. Returns the errors, m.
std::vector<Eigen::Vector3d> georefErrors(const std::filesystem::path& dir,
                                          const Simulation& simulation) {
  const YAML::Node georef = YAML::LoadFile((dir / "georef_truth.yaml").string());
  EXPECT_EQ(georef["epsg"].as<int>(), 3067);
  Eigen::Matrix4d T_epsg_world;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) T_epsg_world(r, c) = georef["T_epsg_world"][r][c].as<double>();
  }
  const geo::CoordinateConverter tm35fin(georef["epsg"].as<int>());
  // The origin's grid coordinates are those of the projection.
  const Eigen::Vector3d origin_grid =
      tm35fin.toProjected({georef["origin"]["latitude_deg"].as<double>(),
                           georef["origin"]["longitude_deg"].as<double>(),
                           georef["origin"]["height_ellipsoid_m"].as<double>()});
  EXPECT_NEAR(georef["origin"]["easting_m"].as<double>(), origin_grid.x(), 1e-6);
  EXPECT_NEAR(georef["origin"]["northing_m"].as<double>(), origin_grid.y(), 1e-6);
  EXPECT_LT((T_epsg_world.block<3, 1>(0, 3) - origin_grid).norm(), 1e-6);

  const Eigen::Matrix4d T_world_epsg = T_epsg_world.inverse();
  std::vector<Eigen::Vector3d> errors;
  for (const GnssFix& fix : gnssFixes(dir)) {
    const Eigen::Vector3d grid =
        tm35fin.toProjected({fix.latitude_deg, fix.longitude_deg, fix.height_ellipsoid_m});
    const Eigen::Vector3d p_world = (T_world_epsg * grid.homogeneous()).head<3>();
    const Eigen::Vector3d truth =
        simulation.motion().at(fix.t_s - kRecordingEpoch_s).T_world_body.translation();
    errors.push_back(p_world - truth);
  }
  return errors;
}

TEST(TruthOutputs, GeorefTruthMapsNoiseFreeFixesOntoTheTrajectory) {
  test::TempDir dir;
  // A turned world frame, so that a georeference that ignores the rotation fails.
  const Simulation simulation(
      smallScenario("gnss: {noise: false, rate_hz: 5, world_yaw_deg: 30}\n"), 20.0, 3);
  writeSimulation(simulation, dir.path());
  const auto errors = georefErrors(dir.path(), simulation);
  ASSERT_EQ(errors.size(), 101u);  // 5 Hz over 20 s, both ends, no outages without noise
  double max_error = 0.0;
  for (const Eigen::Vector3d& e : errors) max_error = std::max(max_error, e.norm());
  EXPECT_LT(max_error, 3e-3);
  std::cout << "noise-free fixes through T_epsg_world^-1: " << max_error * 1e3 << " mm at most\n";
  double farthest = 0.0;  // the fixes are spread out, so the rotation and scale matter
  for (double t = 0.0; t <= 20.0; t += 0.2) {
    farthest = std::max(farthest, simulation.motion().at(t).T_world_body.translation().norm());
  }
  EXPECT_GT(farthest, 5.0);
}

TEST(TruthOutputs, GeorefTruthMapsNoisyFixesWithinTheSimulatedError) {
  test::TempDir dir;
  const Simulation simulation(
      smallScenario("gnss: {rate_hz: 5, multipath_probability: 0, outage_probability: 0}\n"), 20.0,
      3);
  writeSimulation(simulation, dir.path());
  const GnssParams& gnss = simulation.scenario().gnss;
  const double sigma_h_max = gnss.sigma_open_horizontal_m + gnss.sigma_canopy_horizontal_m;
  const auto errors = georefErrors(dir.path(), simulation);
  ASSERT_EQ(errors.size(), 101u);
  double mean_horizontal = 0.0;
  for (const Eigen::Vector3d& e : errors) {
    EXPECT_LT(e.head<2>().norm(), 4.0 * sigma_h_max);
    EXPECT_LT(std::abs(e.z()), 4.0 * gnss.vertical_factor * sigma_h_max);
    mean_horizontal += e.head<2>().norm() / errors.size();
  }
  EXPECT_GT(mean_horizontal, 0.05);  // the noise is there
  EXPECT_GT(mean_horizontal, 0.5 * gnss.sigma_open_horizontal_m);
}

TEST(TruthOutputs, ScenarioYamlReproducesTheRecording) {
  test::TempDir first, second;
  const Scenario scenario =
      smallScenario("duration_s: 1.0\nforest: {stems_per_ha: 1100}\nimu: {rate_hz: 250}\n");
  writeSimulation(Simulation(scenario, scenario.duration_s, 5), first.path());

  Scenario reread = scenarioByName("mixed");  // the file sets every field, the name included
  applyScenarioOverrides(first.file("scenario.yaml"), reread);
  EXPECT_EQ(reread.name, "handheld-loop");
  EXPECT_DOUBLE_EQ(reread.duration_s, 1.0);
  writeSimulation(Simulation(reread, reread.duration_s, 5), second.path());
  for (const char* file : {"recording.bag", "groundtruth.tum", "trees.csv", "georef_truth.yaml",
                           "scenario.yaml", "rig.yaml"}) {
    SCOPED_TRACE(file);
    const std::string a = readFile(first.file(file)), b = readFile(second.file(file));
    EXPECT_GT(a.size(), 100u);
    EXPECT_TRUE(a == b);
  }

  // handheld-loop's IMU reports its orientation; it reads back as ENU (REP-103).
  SystemConfig config;
  io::readConfigYaml(first.file("rig.yaml"), config);
  io::Recording recording =
      io::openRecording(first.file("recording.bag"), config.recording, config.rig);
  std::size_t with_orientation = 0, imu = 0;
  while (auto event = recording.next()) {
    if (const auto* sample = std::get_if<ImuSample>(&*event)) {
      ++imu;
      if (sample->orientation && sample->orientation->reference == OrientationReference::kEnu)
        ++with_orientation;
    }
  }
  EXPECT_EQ(imu, 251u);  // 250 Hz over 1 s, both ends
  EXPECT_EQ(with_orientation, imu);
}

TEST(TruthOutputs, AnUnknownGeorefCodeFailsBeforeTheRecording) {
  test::TempDir dir;
  const Simulation simulation(smallScenario("gnss: {georef_epsg: 4326}\n"), 0.5, 2);
  try {
    writeSimulation(simulation, dir.path());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("EPSG:4326: 'WGS 84' is not a projected CRS"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("recording.bag")));
}

}  // namespace
}  // namespace taiga::sim
