// Every preset shipped in config/ must load and validate.
#include <gtest/gtest.h>

#include <filesystem>

#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"

namespace taiga::io {
namespace {

TEST(ConfigPresets, AllLoadAndValidate) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator("config")) {
    if (entry.path().extension() != ".yaml") continue;
    SystemConfig config;
    EXPECT_NO_THROW(readConfigYaml(entry.path(), config)) << entry.path();
    ++count;
  }
  EXPECT_GT(count, 0) << "no presets found in config/ (tests run from the source directory)";
}

TEST(ConfigPresets, Os0ExtrinsicsMatchTheSensorMetadata) {
  SystemConfig config;
  readConfigYaml("config/os0-128-handheld.yaml", config);
  // The lidar origin is 36.18 mm above the sensor base, the IMU 7.645 mm; yaw 180 degrees.
  const lie::SE3& T_body_lidar = config.rig.T_body_lidar;
  EXPECT_NEAR(T_body_lidar.translation().z(), 0.036180 - 0.007645, 1e-9);
  EXPECT_TRUE((T_body_lidar.rotation() * Eigen::Vector3d::UnitX())
                  .isApprox(-Eigen::Vector3d::UnitX(), 1e-12));
}

}  // namespace
}  // namespace taiga::io
