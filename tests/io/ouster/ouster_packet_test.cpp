// Packet decoding: synthetic packets of every profile with known field values, the real packets of
// the fixtures (CRC, identity), and arbitrary bytes (never a crash, always a status).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <limits>
#include <numbers>
#include <random>

#include "ouster_test_support.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/ouster/frame_assembler.hpp"
#include "taiga/io/ouster/imu_packet.hpp"
#include "taiga/io/ouster/lidar_packet.hpp"

namespace taiga::io::ouster {
namespace {

using test::ousterData;
using test::putLe;

std::span<const std::uint8_t> bytesOf(const std::vector<std::uint8_t>& v) { return v; }

SensorInfo infoOf(const std::string& json) { return readSensorInfo(ousterData(json)); }

/// A packet of `info`'s profile whose pixel (column c, row r) has range 1000 + 8 (c * 200 + r)
/// mm and reflectivity (c + r) % 256; column c has measurement id first_id + c and timestamp
/// 5e9 + c * 1e5 ns. `valid_columns` marks the valid ones (all by default).
std::vector<std::uint8_t> makeLidarPacket(const SensorInfo& info, std::uint16_t frame_id,
                                          int first_id, std::vector<bool> valid_columns = {}) {
  const LidarPacketLayout L = LidarPacketLayout::of(info);
  const bool legacy = L.profile == LidarProfile::kLegacy;
  std::vector<std::uint8_t> p;
  if (!legacy) {
    putLe(p, 1, 2);  // packet type
    putLe(p, frame_id, 2);
    putLe(p, info.initialization_id.value_or(0), 3);
    putLe(p, info.serial_number.value_or(0), 5);
    p.resize(L.packet_header_bytes, 0);
  }
  for (int c = 0; c < L.columns_per_packet; ++c) {
    const bool valid = valid_columns.empty() || valid_columns[static_cast<std::size_t>(c)];
    const std::size_t start = p.size();
    putLe(p, 5'000'000'000ULL + static_cast<std::uint64_t>(c) * 100'000, 8);
    putLe(p, static_cast<std::uint64_t>(first_id + c), 2);
    if (legacy) {
      putLe(p, frame_id, 2);
      putLe(p, 0, 4);  // encoder count
    } else {
      putLe(p, valid ? 1 : 0, 2);
    }
    for (int r = 0; r < L.pixels_per_column; ++r) {
      const std::uint32_t range = 1000 + 8 * static_cast<std::uint32_t>(c * 200 + r);
      const auto refl = static_cast<std::uint8_t>((c + r) % 256);
      const std::size_t pixel = p.size();
      switch (L.profile) {
        case LidarProfile::kRng15Rfl8Nir8:
        case LidarProfile::kRng15Rfl8Nir8Zone16:
        case LidarProfile::kRng15Rfl8Nir8Dual:
          putLe(p, (range >> 3) | 0x8000U, 2);  // the top bit is a flag
          p.push_back(refl);
          p.push_back(0x12);  // near IR / 16
          if (L.profile == LidarProfile::kRng15Rfl8Nir8Dual) {
            putLe(p, (range + 504) >> 3, 2);
            p.push_back(refl / 2);
          }
          break;
        case LidarProfile::kRng19Rfl8Sig16Nir16Dual:
          putLe(p, range | (0x1FU << 19) | (static_cast<std::uint32_t>(refl) << 24), 4);
          putLe(p, (range + 504) | (static_cast<std::uint32_t>(refl / 2) << 24), 4);
          putLe(p, 77, 2);   // signal
          putLe(p, 78, 2);   // signal 2
          putLe(p, 300, 2);  // near IR
          break;
        default:  // LEGACY and RNG19_RFL8_SIG16_NIR16 (flags bits above the range are ignored)
          putLe(p, range | (legacy ? 0U : (0x1FU << 19)), 4);
          putLe(p, refl, 2);
          putLe(p, 77, 2);   // signal
          putLe(p, 300, 2);  // near IR
          break;
      }
      p.resize(pixel + L.pixel_bytes, 0);
    }
    if (legacy) putLe(p, valid ? 0xFFFFFFFFU : 0U, 4);
    EXPECT_EQ(p.size() - start, L.column_bytes);
  }
  if (!legacy) {
    p.resize(L.packet_bytes - 8, 0);
    putLe(p, crc64(p), 8);
  }
  EXPECT_EQ(p.size(), L.packet_bytes);
  return p;
}

TEST(OusterPacket, Crc64IsTheXzVariant) {
  const std::string check = "123456789";
  const std::vector<std::uint8_t> bytes(check.begin(), check.end());
  EXPECT_EQ(crc64(bytes), 0x995DC9BBDF1939FAULL);
  EXPECT_EQ(crc64({}), 0ULL);
}

TEST(OusterPacket, LayoutsMatchTheCapturedPacketSizes) {
  EXPECT_EQ(LidarPacketLayout::of(infoOf("OS-0-128-U1_v2.3.0_1024x10.json")).packet_bytes, 8448u);
  EXPECT_EQ(LidarPacketLayout::of(infoOf("OS-2-128-U1_v2.3.0_1024x10.json")).packet_bytes, 24832u);
  EXPECT_EQ(LidarPacketLayout::of(infoOf("OS-1-64_sensor_config_reduced.json")).packet_bytes,
            12608u);
  EXPECT_EQ(ImuPacketLayout::of(infoOf("imu_zm_no_lidar_0.json")).packet_bytes, 452u);
  EXPECT_EQ(ImuPacketLayout::of(infoOf("crc_test.json")).packet_bytes, 48u);
}

struct ProfileCase {
  const char* json;
  LidarProfile profile;
};

std::ostream& operator<<(std::ostream& os, const ProfileCase& c) {
  return os << profileName(c.profile);
}

class OusterPacketProfiles : public ::testing::TestWithParam<ProfileCase> {};

TEST_P(OusterPacketProfiles, DecodesEveryFieldOfASyntheticPacket) {
  SensorInfo info = infoOf(GetParam().json);
  info.lidar_profile = GetParam().profile;
  info.lidar_profile_name = std::string(profileName(GetParam().profile));
  std::vector<bool> valid(static_cast<std::size_t>(info.columns_per_packet), true);
  valid[3] = false;
  const auto bytes = makeLidarPacket(info, 1234, 32, valid);
  const LidarPacketDecoder decoder(info, {.crc = CrcCheck::kAlways});
  LidarPacket packet;
  ASSERT_EQ(decoder.decode(bytes, packet), PacketStatus::kOk);
  EXPECT_EQ(packet.frame_id, 1234u);
  ASSERT_EQ(packet.columns.size(), static_cast<std::size_t>(info.columns_per_packet));
  const auto pixels = static_cast<std::size_t>(info.pixels_per_column);
  for (std::size_t c = 0; c < packet.columns.size(); ++c) {
    EXPECT_EQ(packet.columns[c].measurement_id, 32 + c);
    EXPECT_EQ(packet.columns[c].timestamp_ns, 5'000'000'000ULL + c * 100'000);
    EXPECT_EQ(packet.columns[c].valid, c != 3);
    for (std::size_t r = 0; r < pixels; r += 7) {
      EXPECT_EQ(packet.range_mm[c * pixels + r], 1000 + 8 * (c * 200 + r)) << c << " " << r;
      EXPECT_EQ(packet.reflectivity[c * pixels + r], (c + r) % 256);
    }
  }
  const LidarProfile profile = info.lidar_profile;
  if (decoder.layout().pixel_bytes <= 8) {  // the low-data-rate profiles
    EXPECT_EQ(packet.near_ir[5], 0x120);
  } else {
    EXPECT_EQ(packet.signal[5], 77);
    EXPECT_EQ(packet.near_ir[5], 300);
  }
  const bool dual = profile == LidarProfile::kRng19Rfl8Sig16Nir16Dual ||
                    profile == LidarProfile::kRng15Rfl8Nir8Dual;
  EXPECT_EQ(decoder.layout().dual_return, dual);
  if (dual) {
    EXPECT_EQ(packet.range2_mm[0], 1504u);
    EXPECT_EQ(packet.reflectivity2[2], 1);
  } else {
    EXPECT_TRUE(packet.range2_mm.empty());
  }
}

INSTANTIATE_TEST_SUITE_P(
    OusterAllProfiles, OusterPacketProfiles,
    ::testing::Values(ProfileCase{"OS-1-64_sensor_config_reduced.json", LidarProfile::kLegacy},
                      ProfileCase{"crc_test.json", LidarProfile::kRng15Rfl8Nir8},
                      ProfileCase{"crc_test.json", LidarProfile::kRng19Rfl8Sig16Nir16},
                      ProfileCase{"crc_test.json", LidarProfile::kRng19Rfl8Sig16Nir16Dual},
                      ProfileCase{"crc_test.json", LidarProfile::kRng15Rfl8Nir8Dual},
                      ProfileCase{"crc_test.json", LidarProfile::kRng19Rfl8Sig16Nir16Zone16},
                      ProfileCase{"crc_test.json", LidarProfile::kRng15Rfl8Nir8Zone16}));

TEST(OusterPacket, DropsPacketsOfTheWrongSizeTypeCrcOrSensor) {
  const SensorInfo info = infoOf("crc_test.json");
  const LidarPacketDecoder decoder(info);
  ASSERT_TRUE(decoder.verifiesCrc());
  const auto real = test::payloadsOfSize(ousterData("crc_test.pcap"), 8448);
  ASSERT_EQ(real.size(), 34u);
  LidarPacket packet;
  for (const auto& bytes : real) ASSERT_EQ(decoder.decode(bytes, packet), PacketStatus::kOk);

  auto corrupted = real[5];
  corrupted[1000] ^= 0x01;
  EXPECT_EQ(decoder.decode(corrupted, packet), PacketStatus::kBadCrc);
  EXPECT_EQ(LidarPacketDecoder(info, {.crc = CrcCheck::kNever}).decode(corrupted, packet),
            PacketStatus::kOk);

  EXPECT_EQ(decoder.decode(bytesOf(real[0]).first(8447), packet), PacketStatus::kWrongSize);
  auto longer = real[0];
  longer.push_back(0);
  EXPECT_EQ(decoder.decode(longer, packet), PacketStatus::kWrongSize);
  EXPECT_EQ(LidarPacketDecoder(info, {.allow_trailing_byte = true}).decode(longer, packet),
            PacketStatus::kOk);
  EXPECT_EQ(decoder.decode({}, packet), PacketStatus::kWrongSize);

  auto imu_type = real[0];
  imu_type[0] = 2;
  EXPECT_EQ(decoder.decode(imu_type, packet), PacketStatus::kWrongPacketType);

  SensorInfo other = info;
  other.serial_number = 122247000786;
  EXPECT_EQ(LidarPacketDecoder(other).decode(real[0], packet), PacketStatus::kOtherSensor);
  EXPECT_EQ(LidarPacketDecoder(other, {.check_sensor_id = false}).decode(real[0], packet),
            PacketStatus::kOk);
}

TEST(OusterPacket, Firmware2FootersAreNotCrcs) {
  const SensorInfo info = infoOf("OS-0-128-U1_v2.3.0_1024x10.json");
  const auto real = test::payloadsOfSize(ousterData("OS-0-128-U1_v2.3.0_1024x10.pcap"), 8448);
  LidarPacket packet;
  EXPECT_FALSE(LidarPacketDecoder(info).verifiesCrc());
  EXPECT_EQ(LidarPacketDecoder(info).decode(real[0], packet), PacketStatus::kOk);
  EXPECT_EQ(LidarPacketDecoder(info, {.crc = CrcCheck::kAlways}).decode(real[0], packet),
            PacketStatus::kBadCrc);
}

TEST(OusterPacket, DecodesLegacyImuPacketsInSiUnits) {
  const SensorInfo info = infoOf("OS-0-128-U1_v2.3.0_1024x10.json");
  std::vector<std::uint8_t> bytes;
  putLe(bytes, 1'000'000'000, 8);  // system time
  putLe(bytes, 2'000'000'000, 8);  // accelerometer time
  putLe(bytes, 3'000'000'000, 8);  // gyroscope time
  for (float v : {0.5f, -1.0f, 2.0f, 90.0f, -180.0f, 45.0f})
    putLe(bytes, std::bit_cast<std::uint32_t>(v), 4);
  const ImuPacketDecoder decoder(info);
  std::vector<ImuSample> samples;
  ASSERT_EQ(decoder.decode(bytes, samples), PacketStatus::kOk);
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_DOUBLE_EQ(samples[0].t_s, 3.0);
  EXPECT_TRUE(samples[0].acceleration_imu_mps2.isApprox(Eigen::Vector3d(0.5, -1.0, 2.0) *
                                                        kStandardGravity_mps2));
  EXPECT_TRUE(samples[0].angular_velocity_imu_radps.isApprox(
      Eigen::Vector3d(std::numbers::pi / 2, -std::numbers::pi, std::numbers::pi / 4)));
  EXPECT_EQ(decoder.decode(bytesOf(bytes).first(47), samples), PacketStatus::kWrongSize);
  EXPECT_TRUE(samples.empty());

  // A NaN value makes the sample unusable, not the stream.
  auto nan = bytes;
  const auto quiet_nan = std::bit_cast<std::uint32_t>(std::numeric_limits<float>::quiet_NaN());
  for (int i = 0; i < 4; ++i)
    nan[24 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(quiet_nan >> (8 * i));
  int skipped = 0;
  EXPECT_EQ(decoder.decode(nan, samples, &skipped), PacketStatus::kOk);
  EXPECT_TRUE(samples.empty());
  EXPECT_EQ(skipped, 1);
}

TEST(OusterPacket, DecodesAccel32Gyro32NmeaPackets) {
  const SensorInfo info = infoOf("imu_zm_no_lidar_0.json");
  const auto real = test::payloadsOfSize(ousterData("imu_zm_no_lidar.pcap"), 452);
  ASSERT_EQ(real.size(), 8u);
  const ImuPacketDecoder decoder(info);
  EXPECT_TRUE(decoder.verifiesCrc());
  std::vector<ImuSample> samples;
  ASSERT_EQ(decoder.decode(real[0], samples), PacketStatus::kOk);
  ASSERT_EQ(samples.size(), 8u);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    // At rest: gravity of about 9.8 m/s^2 along z, rotation rates of a few hundredths of rad/s.
    EXPECT_NEAR(samples[i].acceleration_imu_mps2.norm(), 9.81, 0.35);
    EXPECT_GT(samples[i].acceleration_imu_mps2.z(), 9.5);
    EXPECT_LT(samples[i].angular_velocity_imu_radps.norm(), 0.05);
    if (i > 0) {
      EXPECT_NEAR(samples[i].t_s - samples[i - 1].t_s, 1.5625e-3, 2e-5);
    }
  }
  EXPECT_NEAR(samples[0].t_s, 16177.228652952, 1e-9);
  EXPECT_NEAR(samples[0].acceleration_imu_mps2.x(), 0.0958, 1e-4);

  auto corrupted = real[0];
  corrupted[200] ^= 0x40;
  EXPECT_EQ(decoder.decode(corrupted, samples), PacketStatus::kBadCrc);
  auto lidar_type = real[0];
  lidar_type[0] = 1;
  EXPECT_EQ(decoder.decode(lidar_type, samples), PacketStatus::kWrongPacketType);
  SensorInfo other = info;
  other.serial_number = 1;
  EXPECT_EQ(ImuPacketDecoder(other).decode(real[0], samples), PacketStatus::kOtherSensor);
  // Invalid measurements (status bit 0 clear) are skipped.
  auto invalid = real[0];
  invalid[132 + 10] = 0;  // status of the first measurement
  EXPECT_EQ(ImuPacketDecoder(info, {.crc = CrcCheck::kNever}).decode(invalid, samples),
            PacketStatus::kOk);
  EXPECT_EQ(samples.size(), 7u);
}

TEST(OusterPacket, ArbitraryBytesNeverCrashTheDecodersOrTheAssembler) {
  std::mt19937 rng(20240917);
  for (const char* json :
       {"OS-0-128-U1_v2.3.0_1024x10.json", "OS-2-128-U1_v2.3.0_1024x10.json",
        "OS-1-64_sensor_config_reduced.json", "crc_test.json", "imu_zm_no_lidar_0.json"}) {
    SCOPED_TRACE(json);
    const SensorInfo info = infoOf(json);
    FrameAssembler assembler(info, {.crc = CrcCheck::kNever});
    const ImuPacketDecoder imu(info, {.crc = CrcCheck::kNever});
    const std::size_t size = assembler.decoder().layout().packet_bytes;
    std::vector<ImuSample> samples;
    std::uniform_int_distribution<int> byte(0, 255);
    for (int trial = 0; trial < 60; ++trial) {
      // Exact sizes are the interesting case: they pass the size check.
      const std::size_t n = trial % 3 == 0   ? static_cast<std::size_t>(rng() % (2 * size + 2))
                            : trial % 3 == 1 ? size
                                             : imu.layout().packet_bytes;
      std::vector<std::uint8_t> bytes(n);
      for (auto& b : bytes) b = static_cast<std::uint8_t>(byte(rng));
      if (n >= 2 && trial % 2 == 0) {  // a lidar packet type
        bytes[0] = 1;
        bytes[1] = 0;
      }
      assembler.addPacket(bytes);
      imu.decode(bytes, samples);
      for (const ImuSample& s : samples) EXPECT_TRUE(s.acceleration_imu_mps2.allFinite());
    }
    assembler.finish();
    while (auto frame = assembler.nextFrame()) {
      EXPECT_TRUE(frame->scan.cloud_in_lidar.isConsistent());
      for (const auto& p : frame->scan.cloud_in_lidar.positions) EXPECT_TRUE(p.allFinite());
      for (auto column : frame->scan.cloud_in_lidar.columns)
        EXPECT_LT(column, info.columns_per_frame);
    }
    EXPECT_EQ(assembler.stats().packets, 60u);
  }
}

}  // namespace
}  // namespace taiga::io::ouster
