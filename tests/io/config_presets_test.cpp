// Every preset shipped in config/ must load and validate.
#include <gtest/gtest.h>

#include "taiga/io/ouster/sensor_info.hpp"

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
  // taiga's Ouster decoder gives points in the sensor frame and the body is the IMU, so the
  // preset's T_body_lidar must be T_imu_sensor from the sensor's own metadata.
  const ouster::SensorInfo info = ouster::readSensorInfo("../shared/data/ouster/OS-0-128-U1_v2.3.0_1024x10.json");
  const lie::SE3 T_imu_sensor = info.T_sensor_imu.inverse();
  const lie::SE3& T_body_lidar = config.rig.T_body_lidar;
  EXPECT_LT((T_body_lidar.translation() - T_imu_sensor.translation()).norm(), 1e-9);
  EXPECT_LT((T_body_lidar.rotation().inverse() * T_imu_sensor.rotation()).angle(), 1e-9);
  EXPECT_NEAR(T_body_lidar.translation().z(), -0.007645, 1e-9);
}

}  // namespace
}  // namespace taiga::io
