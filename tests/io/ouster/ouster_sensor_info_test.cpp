#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "../../support/temp_dir.hpp"
#include "ouster_test_support.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/ouster/packet_layout.hpp"
#include "taiga/io/ouster/sensor_info.hpp"

namespace taiga::io::ouster {
namespace {

using nlohmann::json;
using test::messageOf;
using test::ousterData;
using ::testing::HasSubstr;

std::vector<std::filesystem::path> allMetadataFiles() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(ousterData("metadata")))
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  for (const auto& entry : std::filesystem::directory_iterator(ousterData("")))
    if (entry.path().extension() == ".json" &&
        entry.path().filename().string().find("digest") == std::string::npos)
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(OusterSensorInfo, EveryFixtureParsesToAConsistentDescription) {
  const auto files = allMetadataFiles();
  ASSERT_GE(files.size(), 26u + 7u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    const SensorInfo info = readSensorInfo(file);
    EXPECT_EQ(info.source, file.string());
    EXPECT_GT(info.columns_per_frame, 0);
    EXPECT_EQ(info.columns_per_frame % info.columns_per_packet, 0);
    EXPECT_EQ(static_cast<std::size_t>(info.pixels_per_column),
              info.beam_altitude_angles_deg.size());
    EXPECT_EQ(info.beam_azimuth_angles_deg.size(), info.beam_altitude_angles_deg.size());
    EXPECT_GT(info.windowColumns(), 0);
    EXPECT_LE(info.windowColumns(), info.columns_per_frame);
    EXPECT_GT(info.lidar_origin_to_beam_origin_mm, 0.0);
    EXPECT_NE(info.lidar_profile, LidarProfile::kOther);
    EXPECT_NE(info.imu_profile, ImuProfile::kOther);
    // Every Ouster housing puts the lidar 3-8 cm above the sensor origin, rotated about z.
    EXPECT_NEAR(info.T_sensor_lidar.translation().z(), 0.05, 0.035);
    EXPECT_NO_THROW(LidarPacketLayout::of(info));
    EXPECT_NO_THROW(ImuPacketLayout::of(info));
  }
}

TEST(OusterSensorInfo, ReadsTheLegacyLayoutOfTheOs0Capture) {
  const SensorInfo info = readSensorInfo(ousterData("OS-0-128-U1_v2.3.0_1024x10.json"));
  EXPECT_TRUE(info.legacy_layout);
  EXPECT_FALSE(info.reduced_config);
  EXPECT_EQ(info.product_line, "OS-0-128");
  EXPECT_EQ(info.serial_number, 122150000150u);
  EXPECT_EQ(info.initialization_id, 5431292u);
  ASSERT_TRUE(info.firmware_version);
  EXPECT_EQ(*info.firmware_version, (FirmwareVersion{2, 3, 0}));
  EXPECT_EQ(info.lidar_mode, "1024x10");
  EXPECT_EQ(info.columns_per_frame, 1024);
  EXPECT_EQ(info.columns_per_packet, 16);
  EXPECT_EQ(info.pixels_per_column, 128);
  EXPECT_EQ(info.frames_per_second, 10);
  EXPECT_EQ(info.column_window, (std::array<int, 2>{0, 1023}));
  EXPECT_EQ(info.lidar_profile, LidarProfile::kRng15Rfl8Nir8);
  EXPECT_EQ(info.imu_profile, ImuProfile::kLegacy);
  EXPECT_EQ(info.pixel_shift_by_row.size(), 128u);
  EXPECT_DOUBLE_EQ(info.lidar_origin_to_beam_origin_mm, 27.67);
  EXPECT_TRUE(info.T_lidar_beam.translation().isApprox(Eigen::Vector3d(0.02767, 0, 0)));
  EXPECT_TRUE(info.T_sensor_lidar.translation().isApprox(Eigen::Vector3d(0, 0, 0.03618)));
  EXPECT_TRUE(info.T_sensor_lidar.rotation().matrix().isApprox(
      Eigen::Vector3d(-1, -1, 1).asDiagonal().toDenseMatrix()));
  EXPECT_TRUE(
      info.T_sensor_imu.translation().isApprox(Eigen::Vector3d(0.006253, -0.011775, 0.007645)));
  EXPECT_EQ(info.udp_port_lidar, 7502);
  EXPECT_EQ(info.udp_port_imu, 7503);
  EXPECT_TRUE(info.defaulted_fields.empty());
}

TEST(OusterSensorInfo, ReadsTheNestedLayoutWithWindowAndNewImuProfile) {
  const SensorInfo windowed = readSensorInfo(ousterData("windowed_frame2_0.json"));
  EXPECT_FALSE(windowed.legacy_layout);
  EXPECT_EQ(windowed.column_window, (std::array<int, 2>{370, 85}));
  EXPECT_EQ(windowed.windowColumns(), 512 - 370 + 86);
  EXPECT_TRUE(windowed.inWindow(511));
  EXPECT_TRUE(windowed.inWindow(0));
  EXPECT_FALSE(windowed.inWindow(86));
  EXPECT_FALSE(windowed.inWindow(369));
  EXPECT_FALSE(windowed.inWindow(512));

  const SensorInfo zm = readSensorInfo(ousterData("imu_zm_no_lidar_0.json"));
  EXPECT_EQ(zm.imu_profile, ImuProfile::kAccel32Gyro32Nmea);
  EXPECT_EQ(zm.imu_measurements_per_packet, 8);
  EXPECT_EQ(ImuPacketLayout::of(zm).packet_bytes, 452u);
  EXPECT_EQ(zm.lidar_profile, LidarProfile::kRng19Rfl8Sig16Nir16Zone16);
  EXPECT_EQ(zm.udp_port_lidar, 0);
  EXPECT_EQ(zm.udp_port_imu, 7513);
  ASSERT_TRUE(zm.firmware_version);
  EXPECT_EQ(*zm.firmware_version, (FirmwareVersion{3, 2, 0}));
  EXPECT_TRUE(verifiesCrc(zm, CrcCheck::kAuto));

  const SensorInfo crc = readSensorInfo(ousterData("crc_test.json"));
  EXPECT_TRUE(crc.T_lidar_beam.translation().isApprox(Eigen::Vector3d(0.027116, 0, 0)));
  EXPECT_TRUE(verifiesCrc(crc, CrcCheck::kAuto));
  EXPECT_FALSE(
      verifiesCrc(readSensorInfo(ousterData("OS-0-128-U1_v2.3.0_1024x10.json")), CrcCheck::kAuto));
}

TEST(OusterSensorInfo, LegacyAndNestedFilesOfOneSensorAgree) {
  for (const std::string stem :
       {"2_2_os-992119000444-128", "2_5_0_os-992146000760-128", "3_0_1_os-122246000293-128"}) {
    SCOPED_TRACE(stem);
    const SensorInfo nested = readSensorInfo(ousterData("metadata/" + stem + ".json"));
    const SensorInfo legacy = readSensorInfo(ousterData("metadata/" + stem + "_legacy.json"));
    EXPECT_FALSE(nested.legacy_layout);
    EXPECT_TRUE(legacy.legacy_layout);
    EXPECT_EQ(nested.beam_altitude_angles_deg, legacy.beam_altitude_angles_deg);
    EXPECT_EQ(nested.beam_azimuth_angles_deg, legacy.beam_azimuth_angles_deg);
    EXPECT_EQ(nested.columns_per_frame, legacy.columns_per_frame);
    EXPECT_EQ(nested.column_window, legacy.column_window);
    EXPECT_EQ(nested.lidar_profile, legacy.lidar_profile);
    EXPECT_EQ(nested.serial_number, legacy.serial_number);
    EXPECT_EQ(nested.T_lidar_beam.matrix(), legacy.T_lidar_beam.matrix());
    EXPECT_EQ(nested.T_sensor_lidar.matrix(), legacy.T_sensor_lidar.matrix());
    EXPECT_EQ(nested.T_sensor_imu.matrix(), legacy.T_sensor_imu.matrix());
  }
}

TEST(OusterSensorInfo, OldFirmwareGetsDocumentedDefaults) {
  // Firmware 1.12 answered get_lidar_data_format with an error string and had no beam origin.
  const SensorInfo old = readSensorInfo(ousterData("metadata/1_12_os1-991913000010-64.json"));
  EXPECT_EQ(old.columns_per_frame, 1024);
  EXPECT_EQ(old.pixels_per_column, 64);
  EXPECT_EQ(old.lidar_profile, LidarProfile::kLegacy);
  EXPECT_DOUBLE_EQ(old.lidar_origin_to_beam_origin_mm, 12.163);  // gen-1 OS-1
  EXPECT_THAT(old.defaulted_fields,
              ::testing::Contains(std::string("beam_intrinsics.lidar_origin_to_beam_origin_mm")));
  EXPECT_EQ(LidarPacketLayout::of(old).packet_bytes, 12608u);
}

TEST(OusterSensorInfo, ReducedConfigUsesGenOneDefaultsAndSaysSo) {
  const SensorInfo info = readSensorInfo(ousterData("OS-1-64_sensor_config_reduced.json"));
  EXPECT_TRUE(info.reduced_config);
  EXPECT_EQ(info.columns_per_frame, 1024);
  EXPECT_EQ(info.pixels_per_column, 64);
  EXPECT_EQ(info.lidar_profile, LidarProfile::kLegacy);
  EXPECT_EQ(LidarPacketLayout::of(info).packet_bytes, 12608u);
  EXPECT_DOUBLE_EQ(info.lidar_origin_to_beam_origin_mm, 12.163);
  EXPECT_TRUE(info.T_sensor_lidar.translation().isApprox(Eigen::Vector3d(0, 0, 0.03618)));
  EXPECT_FALSE(info.serial_number);
  EXPECT_THAT(info.defaulted_fields,
              ::testing::IsSupersetOf({std::string("lidar_to_sensor_transform"),
                                       std::string("imu_to_sensor_transform"),
                                       std::string("lidar_origin_to_beam_origin_mm")}));
}

// ---- errors -------------------------------------------------------------------------------

json os0Json() {
  return json::parse(test::readBytes(ousterData("OS-0-128-U1_v2.3.0_1024x10.json")));
}
json crcJson() { return json::parse(test::readBytes(ousterData("crc_test.json"))); }

std::string errorOf(const json& document) {
  return messageOf<InputError>([&] { parseSensorInfo(document.dump(), "edited.json"); });
}

TEST(OusterSensorInfo, MissingOrMalformedFieldsNameTheFileAndTheField) {
  json j = crcJson();
  j["beam_intrinsics"].erase("beam_altitude_angles");
  EXPECT_THAT(errorOf(j), HasSubstr("edited.json: field 'beam_intrinsics.beam_altitude_angles': "
                                    "expected an array of beam angles in degrees"));
  EXPECT_THAT(errorOf(j), HasSubstr("found nothing (the field is missing)"));

  j = crcJson();
  j["beam_intrinsics"]["beam_azimuth_angles"].erase(3);
  EXPECT_THAT(errorOf(j), HasSubstr("'beam_intrinsics.beam_azimuth_angles': expected an array of "
                                    "beam angles in degrees, one per beam (128 values"));

  j = crcJson();
  j["beam_intrinsics"]["beam_altitude_angles"][5] = "up";
  EXPECT_THAT(errorOf(j), HasSubstr("field 'beam_intrinsics.beam_altitude_angles[5]': expected a "
                                    "finite number, found the string \"up\""));

  j = crcJson();
  j["lidar_intrinsics"].erase("lidar_to_sensor_transform");
  EXPECT_THAT(errorOf(j), HasSubstr("field 'lidar_intrinsics.lidar_to_sensor_transform': expected "
                                    "16 numbers"));

  j = crcJson();
  j["imu_intrinsics"]["imu_to_sensor_transform"][0] = 2.0;
  EXPECT_THAT(errorOf(j), HasSubstr("'imu_intrinsics.imu_to_sensor_transform': the 3x3 block is "
                                    "not a rotation"));

  j = crcJson();
  j["lidar_data_format"]["pixels_per_column"] = 64;
  EXPECT_THAT(errorOf(j), HasSubstr("field 'lidar_data_format.pixels_per_column' = 64 does not "
                                    "match the 128 beams"));

  j = crcJson();
  j["lidar_data_format"]["column_window"] = json::array({0, 512});
  EXPECT_THAT(errorOf(j), HasSubstr("'lidar_data_format.column_window[1]': expected an integer in "
                                    "[0, 511], found the number 512"));

  j = crcJson();
  j["lidar_data_format"].erase("columns_per_frame");
  j["config_params"]["lidar_mode"] = "fast";
  EXPECT_THAT(errorOf(j), HasSubstr("'config_params.lidar_mode': expected a lidar mode such as "
                                    "\"1024x10\", found the string \"fast\""));

  j = os0Json();
  j["prod_sn"] = "12AB";
  EXPECT_THAT(errorOf(j), HasSubstr("field 'prod_sn': expected a serial number of digits"));

  j = os0Json();
  j["image_rev"] = "ousteros-image-v99999999999.0.0";
  j["build_rev"] = "unknown";
  EXPECT_FALSE(parseSensorInfo(j.dump(), "odd.json").firmware_version);

  j = os0Json();
  j["lidar_to_sensor_transform"][15] = 0;
  EXPECT_THAT(errorOf(j), HasSubstr("last row is 0 0 0 1"));
}

TEST(OusterSensorInfo, RejectsFilesThatAreNotMetadata) {
  EXPECT_THAT(messageOf<InputError>([] { parseSensorInfo("{\"a\": 1", "broken.json"); }),
              HasSubstr("broken.json: not valid JSON"));
  EXPECT_THAT(messageOf<InputError>([] { parseSensorInfo("{\"beam\": 66E666666}", "big.json"); }),
              HasSubstr("big.json: not valid JSON"));  // found by the fuzzer
  EXPECT_THAT(messageOf<InputError>([] { parseSensorInfo("[1, 2]", "list.json"); }),
              HasSubstr("list.json: expected a JSON object at the top level"));
  EXPECT_THAT(
      messageOf<InputError>([] { parseSensorInfo("{\"lidar_mode\": \"1024x10\"}", "m.json"); }),
      HasSubstr("m.json: not Ouster sensor metadata: expected 'beam_intrinsics'"));
  test::TempDir dir;
  EXPECT_THAT(messageOf<InputError>([&] { readSensorInfo(dir.file("none.json")); }),
              HasSubstr("none.json: cannot open: No such file or directory"));
  EXPECT_THAT(messageOf<InputError>([&] { readSensorInfo(dir.path()); }),
              HasSubstr("is a directory"));
}

TEST(OusterSensorInfo, UnknownProfilesReadButCannotBeDecoded) {
  json j = crcJson();
  j["lidar_data_format"]["udp_profile_lidar"] = "RNG99_FUTURE";
  const SensorInfo info = parseSensorInfo(j.dump(), "future.json");
  EXPECT_EQ(info.lidar_profile, LidarProfile::kOther);
  EXPECT_EQ(info.lidar_profile_name, "RNG99_FUTURE");
  EXPECT_THAT(messageOf<InputError>([&] { LidarPacketLayout::of(info); }),
              HasSubstr("future.json: lidar UDP profile 'RNG99_FUTURE' cannot be decoded"));
}

}  // namespace
}  // namespace taiga::io::ouster
