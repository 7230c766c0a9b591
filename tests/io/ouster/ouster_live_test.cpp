// A live sensor's packets over UDP (live.hpp): what arrives on the sockets comes out as the same
// scans and IMU samples as from a capture; lost packets, foreign datagrams and corrupt packets
// are counted; the streams end on the idle timeout and on a stop request.

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "../../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/ouster/beam_geometry.hpp"
#include "taiga/io/ouster/live.hpp"
#include "taiga/io/ouster/packet_encoder.hpp"
#include "taiga/io/udp_socket.hpp"

namespace taiga::io::ouster {
namespace {

/// Ports no other test process uses at the same time.
std::uint16_t testPort(int k) {
  return static_cast<std::uint16_t>(30000 + (getpid() % 5000) * 4 + k);
}

SensorInfo sensor() {
  SensorInfo info;
  info.source = "live test";
  info.serial_number = 990000000007;
  info.initialization_id = 7;
  info.firmware = "v3.1.0";
  info.firmware_version = FirmwareVersion{3, 1, 0};
  info.columns_per_frame = 512;
  info.pixels_per_column = 16;
  info.frames_per_second = 10;
  info.column_window = {0, 511};
  for (int i = 0; i < 16; ++i) {
    info.beam_altitude_angles_deg.push_back(15.0 - 2.0 * i);
    info.beam_azimuth_angles_deg.push_back(0.0);
  }
  info.lidar_profile = LidarProfile::kRng19Rfl8Sig16Nir16;
  info.lidar_profile_name = "RNG19_RFL8_SIG16_NIR16";
  info.udp_port_lidar = testPort(0);
  info.udp_port_imu = testPort(1);
  return info;
}

/// Frame `k`: every pixel returns at 10 m; column times from 1700000000 + 0.1 k s.
Scan frame(const SensorInfo& info, int k) {
  const BeamGeometry geometry(info);
  Scan scan;
  scan.t_start_s = 1700000000.0 + 0.1 * k;
  scan.t_end_s = scan.t_start_s + 0.1 * 511 / 512;
  for (int c = 0; c < 512; ++c)
    for (int row = 0; row < 16; ++row) {
      scan.cloud_in_lidar.positions.push_back(geometry.pointInSensor(row, c, 10000));
      scan.cloud_in_lidar.times_s.push_back(scan.t_start_s + 0.1 * c / 512);
      scan.cloud_in_lidar.intensities.push_back(50.0f);
      scan.cloud_in_lidar.rings.push_back(static_cast<std::uint16_t>(row));
      scan.cloud_in_lidar.columns.push_back(static_cast<std::uint16_t>(c));
    }
  return scan;
}

struct Received {
  std::vector<Scan> scans;
  std::size_t imu_samples = 0;
};

Received drain(Recording& recording) {
  Received r;
  while (auto event = recording.next()) {
    if (auto* scan = std::get_if<Scan>(&*event)) r.scans.push_back(std::move(*scan));
    if (std::holds_alternative<ImuSample>(*event)) ++r.imu_samples;
  }
  return r;
}

TEST(OusterLive, PacketsFromTheSocketsBecomeScansAndSamplesAndLossesAreCounted) {
  test::TempDir dir;
  const SensorInfo info = sensor();
  const auto metadata = dir.write("sensor.json", sensorInfoJson(info));
  LiveCapture capture(
      {.metadata = metadata, .bind_address = "127.0.0.1", .idle_timeout_s = 0.5});
  Recording recording = capture.recording(RigConfig{});
  std::thread sender([&] {
    UdpSocket lidar = UdpSocket::connected("127.0.0.1", info.udp_port_lidar);
    UdpSocket imu = UdpSocket::connected("127.0.0.1", info.udp_port_imu);
    const LidarPacketEncoder encoder(info);
    for (int k = 0; k < 4; ++k) {
      ImuSample s;
      s.t_s = 1700000000.0 + 0.1 * k + 0.05;
      s.acceleration_imu_mps2 = Eigen::Vector3d(0, 0, 9.81);
      imu.send(encodeImuPacket(info, std::span(&s, 1)).bytes);
      std::vector<EncodedPacket> packets =
          encoder.encode(frame(info, k), static_cast<std::uint16_t>(k));
      for (std::size_t p = 0; p < packets.size(); ++p) {
        if (k == 2 && p == 7) continue;                    // lost on the way
        if (k == 3 && p == 0) packets[p].bytes[200] ^= 1;  // corrupted: fails the CRC
        lidar.send(packets[p].bytes);
        if (p % 8 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    }
    lidar.send(std::vector<std::uint8_t>(100, 0));  // a foreign datagram
  });
  const Received r = drain(recording);
  sender.join();
  ASSERT_EQ(r.scans.size(), 4u);
  EXPECT_EQ(r.imu_samples, 4u);
  EXPECT_EQ(r.scans[0].cloud_in_lidar.size(), 512u * 16u);
  EXPECT_EQ(r.scans[2].cloud_in_lidar.size(), (512u - 16u) * 16u);
  EXPECT_EQ(r.scans[3].cloud_in_lidar.size(), (512u - 16u) * 16u);
  const LiveStats stats = capture.stats();
  EXPECT_EQ(stats.lidar_packets, 4u * 32u - 1u);
  EXPECT_EQ(stats.imu_packets, 4u);
  EXPECT_EQ(stats.other_datagrams, 1u);
  EXPECT_EQ(stats.frames, 4u);
  EXPECT_EQ(stats.incomplete_frames, 2u);
  EXPECT_EQ(stats.missing_columns, 32u);
  EXPECT_EQ(stats.bad_packets, 1u);
  EXPECT_NE(stats.stop_reason.find("no packet"), std::string::npos) << stats.stop_reason;
}

TEST(OusterLive, APortInUseIsNamed) {
  test::TempDir dir;
  const SensorInfo info = sensor();
  const auto metadata = dir.write("sensor.json", sensorInfoJson(info));
  const UdpSocket taken = UdpSocket::bound("127.0.0.1", testPort(2));
  try {
    LiveCapture capture({.metadata = metadata,
                         .bind_address = "127.0.0.1",
                         .lidar_port = testPort(2)});
    FAIL() << "bound a port in use";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("127.0.0.1:{}", testPort(2))),
              std::string::npos)
        << e.what();
  }
}

// Last in the file: the stop request is process-wide and stays set.
TEST(OusterLive, AStopRequestEndsTheStreams) {
  test::TempDir dir;
  const SensorInfo info = sensor();
  const auto metadata = dir.write("sensor.json", sensorInfoJson(info));
  LiveCapture capture(
      {.metadata = metadata, .bind_address = "127.0.0.1", .idle_timeout_s = 0.0});
  Recording recording = capture.recording(RigConfig{});
  std::thread stopper([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    requestLiveStop();
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(drain(recording).scans.empty());
  stopper.join();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  EXPECT_NE(capture.stats().stop_reason.find("stop requested"), std::string::npos);
}

}  // namespace
}  // namespace taiga::io::ouster
