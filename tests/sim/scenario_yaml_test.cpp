// The scenario registry and the YAML overrides of `taiga simulate --overrides`.
#include <gtest/gtest.h>

#include <string>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/sim/scenario_yaml.hpp"

namespace taiga::sim {
namespace {

/// The message of the InputError that applying `yaml` throws ("" when it does not throw).
std::string overrideError(const std::string& yaml, Scenario scenario = Scenario{}) {
  try {
    applyScenarioOverridesText(yaml, "overrides.yaml", scenario);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ScenarioRegistry, NamesDefaultsAndAliases) {
  for (const std::string name :
       {"mixed", "sparse_pine", "dense_spruce", "strip_road", "open-field", "handheld-loop",
        "handheld-long", "harvester"}) {
    EXPECT_EQ(scenarioByName(name).name, name);
  }
  EXPECT_EQ(scenarioByName("open_field").name, "open-field");  // the former name
  EXPECT_EQ(scenarioByName("sparse-pine").name, "sparse_pine");
  EXPECT_EQ(scenarioByName("open_field").forest.stems_per_ha, 3.0);

  EXPECT_DOUBLE_EQ(scenarioByName("mixed").duration_s, 60.0);
  EXPECT_FALSE(scenarioByName("mixed").imu.orientation_output);  // the demo's 6-axis IMU
  const Scenario loop = scenarioByName("handheld-loop");
  EXPECT_DOUBLE_EQ(loop.duration_s, 180.0);
  EXPECT_TRUE(loop.imu.orientation_output);
  EXPECT_DOUBLE_EQ(loop.forest.stems_per_ha, Scenario{}.forest.stems_per_ha);  // mixed stand
  const Scenario long_walk = scenarioByName("handheld-long");
  EXPECT_DOUBLE_EQ(long_walk.duration_s, 900.0);
  EXPECT_GT(long_walk.motion.loop_lobes, 1);
  EXPECT_EQ(scenarioByName("harvester").motion.model, MotionModel::kHarvester);
}

TEST(ScenarioYaml, EveryScenarioRoundTripsExactly) {
  for (const std::string& name : scenarioNames()) {
    SCOPED_TRACE(name);
    const Scenario original = scenarioByName(name);
    const std::string yaml = scenarioYaml(original);
    Scenario read;  // the defaults, overwritten by every field of the file
    read.motion.speed_mps = 0.77;
    applyScenarioOverridesText(yaml, "scenario.yaml", read);
    EXPECT_EQ(scenarioYaml(read), yaml);
    EXPECT_EQ(read.name, original.name);
    EXPECT_EQ(read.motion.speed_mps, original.motion.speed_mps);
    EXPECT_EQ(read.motion.model, original.motion.model);
    EXPECT_EQ(read.forest.species.spruce, original.forest.species.spruce);
  }
}

TEST(ScenarioYaml, OverridesOnlyTheKeysGiven) {
  Scenario scenario = scenarioByName("dense_spruce");
  test::TempDir dir;
  const auto file = dir.write("overrides.yaml",
                              "duration_s: 12.5\n"
                              "forest:\n  stems_per_ha: 700\n  species: {birch: 0.6}\n"
                              "motion: {speed_mps: 0.9, model: handheld}\n"
                              "lidar: {beams: 32, noise: false}\n"
                              "imu: {orientation_output: true, orientation_heading_offset_deg: -12.5}\n"
                              "gnss: {world_yaw_deg: 30, georef_epsg: 32635}\n");
  applyScenarioOverrides(file, scenario);
  EXPECT_EQ(scenario.name, "dense_spruce");  // not in the file
  EXPECT_DOUBLE_EQ(scenario.duration_s, 12.5);
  EXPECT_DOUBLE_EQ(scenario.forest.stems_per_ha, 700.0);
  EXPECT_DOUBLE_EQ(scenario.forest.dbh_mean_m, 0.19);  // dense_spruce's, not in the file
  EXPECT_DOUBLE_EQ(scenario.forest.species.birch, 0.6);
  EXPECT_DOUBLE_EQ(scenario.forest.species.spruce, 0.9);
  EXPECT_DOUBLE_EQ(scenario.motion.speed_mps, 0.9);
  EXPECT_EQ(scenario.lidar.beams, 32);
  EXPECT_FALSE(scenario.lidar.noise);
  EXPECT_TRUE(scenario.imu.orientation_output);
  EXPECT_DOUBLE_EQ(scenario.imu.orientation_heading_offset_deg, -12.5);
  EXPECT_DOUBLE_EQ(scenario.gnss.world_yaw_deg, 30.0);
  EXPECT_EQ(scenario.gnss.georef_epsg, 32635);
}

TEST(ScenarioYaml, UnknownKeysNameTheFileThePathAndTheLikelyKey) {
  const std::string e = overrideError("motion:\n  sped_mps: 1.0\n");

  EXPECT_NE(e.find("overrides.yaml:2:3: motion.sped_mps: unknown key; did you mean 'speed_mps'?"),
            std::string::npos)
      << e;
  EXPECT_NE(overrideError("forest:\n  species: {larch: 0.2}\n").find("forest.species.larch: unknown key"),
            std::string::npos);
  EXPECT_NE(overrideError("weather: rain\n").find("overrides.yaml:1:1: weather: unknown key"),
            std::string::npos);
  EXPECT_NE(overrideError("name: jungle\n").find("name: expected one of mixed,"), std::string::npos);
}

TEST(ScenarioYaml, WrongTypesAreInputErrors) {
  EXPECT_NE(overrideError("lidar:\n  beams: many\n").find("overrides.yaml:2:10: lidar.beams: expected an integer, got 'many'"),
            std::string::npos);
  EXPECT_NE(overrideError("imu: {noise: maybe}\n").find("imu.noise: expected true or false, got 'maybe'"),
            std::string::npos);
  EXPECT_NE(overrideError("gnss: {rate_hz: [1, 2]}\n").find("gnss.rate_hz: expected a finite number"),
            std::string::npos);
  EXPECT_NE(overrideError("motion: fast\n").find("motion: expected a mapping of keys, got 'fast'"),
            std::string::npos);
  EXPECT_NE(overrideError("motion: {model: tractor}\n").find("motion.model: expected one of handheld, harvester"),
            std::string::npos);
}

TEST(ScenarioYaml, ValuesOutOfRangeAreInputErrors) {
  const std::string dbh = overrideError("forest:\n  dbh_mean_m: 2.0\n");
  EXPECT_NE(dbh.find("overrides.yaml:2:3: forest.dbh_mean_m: expected a value in [0.08, 0.5], got 2"),
            std::string::npos)
      << dbh;
  EXPECT_NE(overrideError("lidar: {beams: -1}\n").find("lidar.beams: expected a value in [0, 128]"),
            std::string::npos);
  EXPECT_NE(overrideError("imu: {rate_hz: -200}\n").find("imu.rate_hz: expected a value in"),
            std::string::npos);
  EXPECT_NE(overrideError("forest: {species: {pine: 0, spruce: 0, birch: 0}}\n")
                .find("forest.species.pine: expected at least one share > 0"),
            std::string::npos);
  // The motion model's own checks, with the file's name.
  const std::string speed = overrideError("motion: {speed_mps: -1}\n");
  EXPECT_NE(speed.find("overrides.yaml: motion.speed_mps: expected > 0"), std::string::npos)
      << speed;
  EXPECT_EQ(overrideError("motion: {speed_mps: 1.1}\nlidar: {beams: 64}\n"), "");
}

TEST(ScenarioYaml, MissingFileIsAnInputError) {
  Scenario scenario;
  EXPECT_THROW(applyScenarioOverrides("/nonexistent/overrides.yaml", scenario), InputError);
}

}  // namespace
}  // namespace taiga::sim
