// Encoding scans, IMU samples and metadata as an Ouster sensor sends them (packet_encoder.hpp,
// pcap_writer.hpp): what the decoders read back must be what was encoded, on a real capture's
// frame and on synthetic frames of every supported profile.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ouster_test_support.hpp"
#include "taiga/io/ouster/frame_assembler.hpp"
#include "taiga/io/ouster/imu_packet.hpp"
#include "taiga/io/ouster/packet_encoder.hpp"
#include "taiga/io/ouster/pcap_writer.hpp"

namespace taiga::io::ouster {
namespace {

std::vector<Scan> assemble(const SensorInfo& info, const std::vector<EncodedPacket>& packets,
                           FrameAssemblerStats* stats = nullptr) {
  FrameAssembler assembler(info);
  for (const EncodedPacket& p : packets) EXPECT_EQ(assembler.addPacket(p.bytes), PacketStatus::kOk);
  assembler.finish();
  std::vector<Scan> scans;
  while (auto frame = assembler.nextFrame()) scans.push_back(std::move(frame->scan));
  if (stats != nullptr) *stats = assembler.stats();
  return scans;
}

void expectSamePoints(const PointCloud& a, const PointCloud& b, double tolerance_m) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_LT((a.positions[i] - b.positions[i]).norm(), tolerance_m) << i;
    ASSERT_NEAR(a.times_s[i], b.times_s[i], 1e-6) << i;
    ASSERT_EQ(a.rings[i], b.rings[i]) << i;
    ASSERT_EQ(a.columns[i], b.columns[i]) << i;
    ASSERT_EQ(a.intensities[i], b.intensities[i]) << i;
  }
}

/// A 64-beam 512x10 sensor of `profile` on firmware 3.1 (packets carry the CRC-64).
SensorInfo syntheticInfo(const std::string& profile) {
  SensorInfo info;
  info.source = "synthetic";
  info.product_line = "OS-0-64";
  info.serial_number = 990000000042;
  info.initialization_id = 4242;
  info.firmware = "ousteros-image-prod-aries-v3.1.0+test";
  info.firmware_version = FirmwareVersion{3, 1, 0};
  info.columns_per_frame = 512;
  info.pixels_per_column = 64;
  info.frames_per_second = 10;
  info.column_window = {0, 511};
  for (int i = 0; i < 64; ++i) {
    info.beam_altitude_angles_deg.push_back(45.0 - 90.0 * i / 63.0);
    info.beam_azimuth_angles_deg.push_back(i % 2 == 0 ? 3.05 : -3.05);
  }
  info.lidar_origin_to_beam_origin_mm = 27.67;
  info.T_lidar_beam = lie::SE3(lie::SO3(), Eigen::Vector3d(0.02767, 0.0, 0.0));
  info.T_sensor_lidar = lie::SE3(lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), M_PI),
                                 Eigen::Vector3d(0, 0, 0.03618));
  info.T_sensor_imu = lie::SE3(lie::SO3(), Eigen::Vector3d(0.006253, -0.011775, 0.007645));
  info.udp_port_lidar = 7502;
  info.udp_port_imu = 7503;
  info.lidar_profile_name = profile;
  for (LidarProfile p :
       {LidarProfile::kLegacy, LidarProfile::kRng19Rfl8Sig16Nir16, LidarProfile::kRng15Rfl8Nir8})
    if (profileName(p) == profile) info.lidar_profile = p;
  // Read back from its own JSON: the encoder's metadata must describe its packets.
  return parseSensorInfo(sensorInfoJson(info), "synthetic.json");
}

/// A frame whose points lie on their beams at random ranges (some pixels without a return),
/// on the range quantum of `unit_mm`.
Scan syntheticScan(const SensorInfo& info, int unit_mm, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::uint32_t> range_units(200 / unit_mm, 80000 / unit_mm);
  std::bernoulli_distribution returns(0.8);
  const BeamGeometry geometry(info);
  Scan scan;
  scan.t_start_s = 1700000000.0;
  const double dt_s = 0.1 / info.columns_per_frame;
  scan.t_end_s = scan.t_start_s + (info.columns_per_frame - 1) * dt_s;
  PointCloud& cloud = scan.cloud_in_lidar;
  for (int c = 0; c < info.columns_per_frame; ++c) {
    for (int row = 0; row < info.pixels_per_column; ++row) {
      if (!returns(rng)) continue;
      cloud.positions.push_back(geometry.pointInSensor(row, c, range_units(rng) * unit_mm));
      cloud.times_s.push_back(static_cast<double>(std::llround((scan.t_start_s + c * dt_s) * 1e9)) *
                              1e-9);
      cloud.intensities.push_back(static_cast<float>(rng() % 256));
      cloud.rings.push_back(static_cast<std::uint16_t>(row));
      cloud.columns.push_back(static_cast<std::uint16_t>(c));
    }
  }
  return scan;
}

TEST(OusterEncoder, ARealCapturesFrameSurvivesEncodingAndDecoding) {
  const SensorInfo info = readSensorInfo(test::ousterData("OS-0-128-U1_v2.3.0_1024x10.json"));
  const auto payloads = test::payloadsOfSize(test::ousterData("OS-0-128-U1_v2.3.0_1024x10.pcap"),
                                             LidarPacketLayout::of(info).packet_bytes);
  FrameAssembler assembler(info);
  for (const auto& p : payloads) assembler.addPacket(p);
  assembler.finish();
  const auto frame = assembler.nextFrame();
  ASSERT_TRUE(frame && frame->complete());
  const Scan& real = frame->scan;
  ASSERT_GT(real.cloud_in_lidar.size(), 10000u);

  const std::vector<EncodedPacket> packets =
      LidarPacketEncoder(info).encode(real, static_cast<std::uint16_t>(frame->frame_id));
  EXPECT_EQ(packets.size(), 64u);
  const std::vector<Scan> decoded = assemble(info, packets);
  ASSERT_EQ(decoded.size(), 1u);
  expectSamePoints(decoded[0].cloud_in_lidar, real.cloud_in_lidar, 1e-6);
  EXPECT_DOUBLE_EQ(decoded[0].t_end_s, real.t_end_s);
}

TEST(OusterEncoder, EveryProfileDecodesToTheEncodedPointsWithItsCrc) {
  for (const auto& [profile, unit_mm] :
       {std::pair{"LEGACY", 1}, std::pair{"RNG19_RFL8_SIG16_NIR16", 1},
        std::pair{"RNG15_RFL8_NIR8", 8}}) {
    SCOPED_TRACE(profile);
    const SensorInfo info = syntheticInfo(profile);
    ASSERT_EQ(profileName(info.lidar_profile), profile);
    const Scan scan = syntheticScan(info, unit_mm, 7);
    const std::vector<EncodedPacket> packets = LidarPacketEncoder(info).encode(scan, 9);
    ASSERT_EQ(packets.size(), 32u);
    FrameAssemblerStats stats;
    const std::vector<Scan> decoded = assemble(info, packets, &stats);
    ASSERT_EQ(decoded.size(), 1u);
    EXPECT_EQ(stats.incomplete_frames, 0u);
    expectSamePoints(decoded[0].cloud_in_lidar, scan.cloud_in_lidar, 1e-6);
    if (std::string(profile) != "LEGACY") {  // a flipped bit fails the CRC check
      std::vector<std::uint8_t> bad = packets[3].bytes;
      bad[100] ^= 0x10;
      LidarPacket out;
      EXPECT_EQ(LidarPacketDecoder(info).decode(bad, out), PacketStatus::kBadCrc);
    }
  }
}

TEST(OusterEncoder, APacketWithoutAnyReturnIsNotSentAndTheFrameIsIncomplete) {
  const SensorInfo info = syntheticInfo("RNG19_RFL8_SIG16_NIR16");
  Scan scan = syntheticScan(info, 1, 3);
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < scan.cloud_in_lidar.size(); ++i)
    if (scan.cloud_in_lidar.columns[i] / 16 != 5) kept.push_back(i);  // packet 5 lost
  scan.cloud_in_lidar = scan.cloud_in_lidar.select(kept);
  const std::vector<EncodedPacket> packets = LidarPacketEncoder(info).encode(scan, 1);
  EXPECT_EQ(packets.size(), 31u);
  FrameAssemblerStats stats;
  const std::vector<Scan> decoded = assemble(info, packets, &stats);
  ASSERT_EQ(decoded.size(), 1u);
  EXPECT_EQ(stats.incomplete_frames, 1u);
  expectSamePoints(decoded[0].cloud_in_lidar, scan.cloud_in_lidar, 1e-6);
}

TEST(OusterEncoder, MetadataReadsBackToTheSameSensor) {
  const SensorInfo real = readSensorInfo(test::ousterData("OS-0-128-U1_v2.3.0_1024x10.json"));
  const SensorInfo back = parseSensorInfo(sensorInfoJson(real), "back.json");
  EXPECT_EQ(back.beam_altitude_angles_deg, real.beam_altitude_angles_deg);
  EXPECT_EQ(back.beam_azimuth_angles_deg, real.beam_azimuth_angles_deg);
  EXPECT_EQ(back.columns_per_frame, real.columns_per_frame);
  EXPECT_EQ(back.pixels_per_column, real.pixels_per_column);
  EXPECT_EQ(back.frames_per_second, real.frames_per_second);
  EXPECT_EQ(back.lidar_profile, real.lidar_profile);
  EXPECT_EQ(back.imu_profile, real.imu_profile);
  EXPECT_EQ(back.serial_number, real.serial_number);
  EXPECT_EQ(back.initialization_id, real.initialization_id);
  EXPECT_EQ(back.firmware_version, real.firmware_version);
  EXPECT_EQ(back.udp_port_lidar, real.udp_port_lidar);
  EXPECT_EQ(back.udp_port_imu, real.udp_port_imu);
  EXPECT_NEAR(back.lidar_origin_to_beam_origin_mm, real.lidar_origin_to_beam_origin_mm, 1e-12);
  EXPECT_TRUE(back.T_sensor_lidar.matrix().isApprox(real.T_sensor_lidar.matrix(), 1e-12));
  EXPECT_TRUE(back.T_sensor_imu.matrix().isApprox(real.T_sensor_imu.matrix(), 1e-12));
  EXPECT_TRUE(back.T_lidar_beam.matrix().isApprox(real.T_lidar_beam.matrix(), 1e-12));
}

TEST(OusterEncoder, ImuSamplesReadBackInBothProfiles) {
  SensorInfo info = syntheticInfo("RNG19_RFL8_SIG16_NIR16");
  ImuSample a;
  a.t_s = 1700000000.123456789;
  a.acceleration_imu_mps2 = Eigen::Vector3d(0.1, -0.2, 9.81);
  a.angular_velocity_imu_radps = Eigen::Vector3d(0.01, 0.5, -1.5);
  ImuSample b = a;
  b.t_s += 0.01;
  b.acceleration_imu_mps2.x() = 2.0;
  for (ImuProfile profile : {ImuProfile::kLegacy, ImuProfile::kAccel32Gyro32Nmea}) {
    info.imu_profile = profile;
    info.imu_profile_name = std::string(profileName(profile));
    info.imu_measurements_per_packet = 8;
    const std::vector<ImuSample> in =
        profile == ImuProfile::kLegacy ? std::vector{a} : std::vector{a, b};
    const EncodedPacket packet = encodeImuPacket(info, in);
    std::vector<ImuSample> out;
    ASSERT_EQ(ImuPacketDecoder(info).decode(packet.bytes, out), PacketStatus::kOk);
    ASSERT_EQ(out.size(), in.size());
    for (std::size_t i = 0; i < in.size(); ++i) {
      EXPECT_NEAR(out[i].t_s, in[i].t_s, 1e-6);
      EXPECT_LT((out[i].acceleration_imu_mps2 - in[i].acceleration_imu_mps2).norm(), 1e-5);
      EXPECT_LT((out[i].angular_velocity_imu_radps - in[i].angular_velocity_imu_radps).norm(),
                1e-6);
    }
  }
}

TEST(OusterEncoder, PcapWriterDatagramsReadBack) {
  const auto path = std::filesystem::temp_directory_path() / "taiga_pcap_writer_test.pcap";
  const std::vector<std::uint8_t> big(24832, 0xAB), small{1, 2, 3};
  {
    PcapWriter writer(path);
    writer.write(1700000000123456789, 7502, 7502, big);
    writer.write(1700000000123456999, 7503, 7503, small);
    writer.close();
  }
  PcapReader reader(path);
  const auto first = reader.next();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->destination_port, 7502);
  EXPECT_EQ(first->capture_time_ns, 1700000000123456789);
  EXPECT_TRUE(std::equal(first->payload.begin(), first->payload.end(), big.begin(), big.end()));
  const auto second = reader.next();
  ASSERT_TRUE(second);
  EXPECT_EQ(second->source_port, 7503);
  EXPECT_TRUE(
      std::equal(second->payload.begin(), second->payload.end(), small.begin(), small.end()));
  EXPECT_FALSE(reader.next());
  std::filesystem::remove(path);
}

TEST(OusterEncoder, AnUnwritableCaptureNamesTheFile) {
  try {
    PcapWriter writer("/nonexistent/dir/capture.pcap");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/capture.pcap"), std::string::npos);
  }
}

}  // namespace
}  // namespace taiga::io::ouster
