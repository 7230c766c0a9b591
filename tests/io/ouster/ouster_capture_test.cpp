// Every real capture decodes to the frames, columns and IMU samples that shared/data/README.md
// states, with plausible geometry and timing; the vendor's digests pin the decoded fields.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>

#include "../../support/temp_dir.hpp"
#include "ouster_test_support.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/ouster/capture.hpp"

namespace taiga::io::ouster {
namespace {

using test::ousterData;

struct ExpectedFrame {
  std::uint32_t frame_id;
  int columns;
};

struct CaptureCase {
  const char* pcap;
  const char* json;
  std::vector<ExpectedFrame> frames;
  int columns_expected;  ///< columns of a complete frame (the window)
  std::size_t imu_samples;
  /// Bound on the 99th percentile of the ranges. Single returns reach further (the OS0/OS1
  /// captures hold retroreflectors at up to 247 m); every range stays below the profile's limit.
  double p99_range_m;
};

std::ostream& operator<<(std::ostream& os, const CaptureCase& c) { return os << c.pcap; }

struct Decoded {
  OusterCapture capture;
  std::vector<AssembledFrame> frames;
  std::vector<ImuSample> imu;
};

Decoded decode(const char* pcap, const char* json) {
  Decoded d;
  d.capture = openOusterCaptureStreams(ousterData(pcap), ousterData(json));
  if (d.capture.lidar)
    while (auto frame = d.capture.lidar->nextFrame()) d.frames.push_back(std::move(*frame));
  if (d.capture.imu)
    while (auto event = d.capture.imu->next()) d.imu.push_back(std::get<ImuSample>(*event));
  return d;
}

class OusterCaptures : public ::testing::TestWithParam<CaptureCase> {};

TEST_P(OusterCaptures, DecodeToTheDocumentedFramesColumnsAndImuSamples) {
  const CaptureCase& c = GetParam();
  const Decoded d = decode(c.pcap, c.json);
  ASSERT_EQ(d.frames.size(), c.frames.size());
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    SCOPED_TRACE(i);
    const AssembledFrame& frame = d.frames[i];
    EXPECT_EQ(frame.frame_id, c.frames[i].frame_id);
    EXPECT_EQ(frame.columns_received, c.frames[i].columns);
    EXPECT_EQ(frame.columns_expected, c.columns_expected);
    EXPECT_EQ(frame.scan.index, i);
    const PointCloud& cloud = frame.scan.cloud_in_lidar;
    const SensorInfo& info = d.capture.info;
    ASSERT_TRUE(cloud.isConsistent());
    ASSERT_TRUE(cloud.hasTimes() && cloud.hasRings() && cloud.hasColumns() &&
                cloud.hasIntensities());
    // A good share of the beams of a real scene return.
    EXPECT_GT(cloud.size(), static_cast<std::size_t>(frame.columns_received) *
                                static_cast<std::size_t>(info.pixels_per_column) / 10);

    const double range_limit_m =
        info.lidar_profile == LidarProfile::kRng15Rfl8Nir8 ? 0x7FFF * 8e-3 : 0x7FFFF * 1e-3;
    std::set<std::uint16_t> columns;
    std::vector<double> ranges_m;
    for (std::size_t p = 0; p < cloud.size(); ++p) {
      // Range from the sensor's optical centre (the lidar origin in the sensor frame).
      const double r = (cloud.positions[p] - info.T_sensor_lidar.translation()).norm();
      ASSERT_GT(r, 0.0);
      ASSERT_LT(r, range_limit_m);
      ASSERT_LT(cloud.rings[p], info.pixels_per_column);
      ASSERT_TRUE(info.inWindow(cloud.columns[p])) << cloud.columns[p];
      columns.insert(cloud.columns[p]);
      ranges_m.push_back(r);
    }
    std::sort(ranges_m.begin(), ranges_m.end());
    EXPECT_LT(ranges_m[ranges_m.size() * 99 / 100], c.p99_range_m);
    EXPECT_GT(columns.size(), static_cast<std::size_t>(frame.columns_received) / 2);

    // Column times increase strictly through the frame and span the columns' share of a turn.
    std::vector<double> column_times;
    for (std::size_t p = 0; p < cloud.size(); ++p)
      if (column_times.empty() || cloud.times_s[p] != column_times.back())
        column_times.push_back(cloud.times_s[p]);
    for (std::size_t k = 1; k < column_times.size(); ++k)
      ASSERT_LT(column_times[k - 1], column_times[k]);
    EXPECT_EQ(frame.scan.t_end_s, column_times.back());
    EXPECT_LE(frame.scan.t_start_s, column_times.front());
    // Measurement ids run 0 .. W-1 through one turn, also across a window that wraps.
    const double period_s = 1.0 / info.frames_per_second;
    const double expected_span_s =
        period_s * (cloud.columns.back() - cloud.columns.front()) / info.columns_per_frame;
    EXPECT_NEAR(column_times.back() - column_times.front(), expected_span_s, 0.01 * period_s);
    if (frame.complete() && c.columns_expected == info.columns_per_frame) {
      EXPECT_GT(frame.scan.t_end_s - frame.scan.t_start_s, 0.98 * period_s);
      EXPECT_LT(frame.scan.t_end_s - frame.scan.t_start_s, period_s);
    }
    if (i > 0) {
      EXPECT_GT(frame.scan.t_start_s, d.frames[i - 1].scan.t_end_s);
    }
  }

  EXPECT_EQ(d.imu.size(), c.imu_samples);
  for (std::size_t k = 0; k < d.imu.size(); ++k) {
    // Hand-held or still sensors: about 1 g, slow rotation; catches g or deg/s left unconverted.
    EXPECT_NEAR(d.imu[k].acceleration_imu_mps2.norm(), kStandardGravity_mps2, 2.5);
    EXPECT_LT(d.imu[k].angular_velocity_imu_radps.norm(), 0.5);
    if (k > 0) {
      EXPECT_GT(d.imu[k].t_s, d.imu[k - 1].t_s);
    }
  }
  // Scans and IMU samples share the sensor clock.
  if (!d.frames.empty() && !d.imu.empty()) {
    EXPECT_NEAR(d.imu.front().t_s, d.frames.front().scan.t_start_s, 0.2);
    EXPECT_NEAR(d.imu.back().t_s, d.frames.back().scan.t_end_s, 0.2);
  }
}

INSTANTIATE_TEST_SUITE_P(
    OusterRealCaptures, OusterCaptures,
    ::testing::Values(
        CaptureCase{"OS-0-128-U1_v2.3.0_1024x10.pcap",
                    "OS-0-128-U1_v2.3.0_1024x10.json",
                    {{1491, 1024}},
                    1024,
                    10,
                    120.0},
        CaptureCase{"OS-1-128_v2.3.0_1024x10_lb_n3.pcap",
                    "OS-1-128_v2.3.0_1024x10.json",
                    {{1795, 1024}, {1796, 1024}, {1797, 1024}},
                    1024,
                    30,
                    120.0},
        CaptureCase{"OS-2-128-U1_v2.3.0_1024x10.pcap",
                    "OS-2-128-U1_v2.3.0_1024x10.json",
                    {{1259, 1024}},
                    1024,
                    10,
                    240.0},
        CaptureCase{"OS-1-64_1024x10_fw20.pcap",
                    "OS-1-64_sensor_config_reduced.json",
                    {{189, 1024}},
                    1024,
                    11,
                    120.0},
        CaptureCase{"crc_test.pcap", "crc_test.json", {{254, 512}, {255, 32}}, 512, 10, 120.0},
        // This window faces a retroreflective far scene: 1% of its returns lie beyond 120 m.
        CaptureCase{
            "windowed_frame1.pcap", "windowed_frame1_0.json", {{1553, 256}}, 256, 10, 240.0},
        CaptureCase{
            "windowed_frame2.pcap", "windowed_frame2_0.json", {{1314, 228}}, 228, 10, 120.0},
        CaptureCase{"imu_zm_no_lidar.pcap", "imu_zm_no_lidar_0.json", {}, 2048, 64, 120.0}));

TEST(OusterCapture, FirstOs0ImuSampleReadsAboutOneG) {
  const Decoded d = decode("OS-0-128-U1_v2.3.0_1024x10.pcap", "OS-0-128-U1_v2.3.0_1024x10.json");
  ASSERT_FALSE(d.imu.empty());
  const Eigen::Vector3d expected_g(0.117, 0.006, 1.042);
  EXPECT_LT((d.imu[0].acceleration_imu_mps2 - expected_g * kStandardGravity_mps2).norm(), 0.02);
  EXPECT_NEAR(d.imu[0].t_s, 1462.582413750, 1e-9);  // the gyroscope read time
  EXPECT_EQ(d.capture.probe.lidar_port, 7502);
  EXPECT_EQ(d.capture.probe.imu_port, 7503);
}

TEST(OusterCapture, WindowsDeliverOnlyTheirColumnsAndTheWrappingOneStaysInTimeOrder) {
  const Decoded first = decode("windowed_frame1.pcap", "windowed_frame1_0.json");
  ASSERT_EQ(first.frames.size(), 1u);
  const auto& cols1 = first.frames[0].scan.cloud_in_lidar.columns;
  EXPECT_EQ(*std::min_element(cols1.begin(), cols1.end()), 1);
  EXPECT_EQ(*std::max_element(cols1.begin(), cols1.end()), 256);
  // The lidar port differs from the metadata's; the probe finds it.
  EXPECT_EQ(first.capture.probe.lidar_port, 53750);

  const Decoded second = decode("windowed_frame2.pcap", "windowed_frame2_0.json");
  ASSERT_EQ(second.frames.size(), 1u);
  const PointCloud& cloud = second.frames[0].scan.cloud_in_lidar;
  // [370, 85] wraps: the frame starts at column 0 and ends at column 511.
  EXPECT_EQ(cloud.columns.front(), 0);
  EXPECT_EQ(cloud.columns.back(), 511);
  for (auto column : cloud.columns) EXPECT_TRUE(column <= 85 || column >= 370) << column;
}

TEST(OusterCapture, StreamsDeliverScansAndImuSamplesInTimeOrder) {
  auto streams = openOusterCapture(ousterData("OS-1-128_v2.3.0_1024x10_lb_n3.pcap"),
                                   ousterData("OS-1-128_v2.3.0_1024x10.json"));
  ASSERT_EQ(streams.size(), 2u);
  EXPECT_THAT(streams[0]->name(), ::testing::EndsWith("lb_n3.pcap (lidar)"));
  EXPECT_THAT(streams[1]->name(), ::testing::EndsWith("lb_n3.pcap (IMU)"));
  std::vector<double> scan_ends;
  while (auto event = streams[0]->next()) {
    const Scan& scan = std::get<Scan>(*event);
    EXPECT_EQ(scan.index, scan_ends.size());
    scan_ends.push_back(scan.t_end_s);
  }
  EXPECT_EQ(scan_ends.size(), 3u);
  EXPECT_TRUE(std::is_sorted(scan_ends.begin(), scan_ends.end()));
  EXPECT_FALSE(streams[0]->next());  // stays at the end

  const auto only_imu =
      openOusterCapture(ousterData("imu_zm_no_lidar.pcap"), ousterData("imu_zm_no_lidar_0.json"));
  ASSERT_EQ(only_imu.size(), 1u);
  EXPECT_THAT(only_imu[0]->name(), ::testing::EndsWith("(IMU)"));
}

// ---- vendor digests --------------------------------------------------------------------------

/// MD5 of little-endian integers of `bytes` each, as numpy's tobytes() gives them.
template <class T>
std::string md5Of(const std::vector<T>& values, int bytes = sizeof(T)) {
  std::vector<std::uint8_t> raw;
  for (T v : values) test::putLe(raw, static_cast<std::uint64_t>(v), bytes);
  return test::md5Hex(raw);
}

TEST(OusterCapture, DecodedFieldsMatchTheVendorDigests) {
  for (const std::string stem : {"OS-0-128-U1_v2.3.0_1024x10", "OS-2-128-U1_v2.3.0_1024x10"}) {
    SCOPED_TRACE(stem);
    const SensorInfo info = readSensorInfo(ousterData(stem + ".json"));
    const auto digest = nlohmann::json::parse(test::readBytes(ousterData(stem + "_digest.json")));
    const auto& scan = digest["scans"][0];
    const LidarPacketDecoder decoder(info);
    const auto w = static_cast<std::size_t>(info.columns_per_frame);
    const auto h = static_cast<std::size_t>(info.pixels_per_column);
    // The SDK's LidarScan: per-column arrays and row-major h x w images indexed by measurement id.
    std::vector<std::uint64_t> timestamp(w);
    std::vector<std::uint16_t> measurement_id(w);
    std::vector<std::uint32_t> packet_status;
    std::vector<std::uint32_t> range(w * h);
    std::vector<std::uint8_t> reflectivity(w * h);
    std::vector<std::uint16_t> near_ir(w * h), signal(w * h);
    LidarPacket packet;
    std::uint32_t frame_id = 0;
    for (const auto& bytes :
         test::payloadsOfSize(ousterData(stem + ".pcap"), decoder.layout().packet_bytes)) {
      ASSERT_EQ(decoder.decode(bytes, packet), PacketStatus::kOk);
      frame_id = packet.frame_id;
      for (std::size_t c = 0; c < packet.columns.size(); ++c) {
        const std::size_t id = packet.columns[c].measurement_id;
        timestamp[id] = packet.columns[c].timestamp_ns;
        measurement_id[id] = static_cast<std::uint16_t>(id);
        packet_status.push_back(packet.columns[c].status);
        for (std::size_t row = 0; row < h; ++row) {
          range[row * w + id] = packet.range_mm[c * h + row];
          reflectivity[row * w + id] = static_cast<std::uint8_t>(packet.reflectivity[c * h + row]);
          near_ir[row * w + id] = packet.near_ir[c * h + row];
          signal[row * w + id] = packet.signal[c * h + row];
        }
      }
    }
    EXPECT_EQ(std::to_string(frame_id), scan["FRAME_ID"].get<std::string>());
    EXPECT_EQ(md5Of(timestamp), scan["TIMESTAMP"]);
    EXPECT_EQ(md5Of(measurement_id), scan["MEASUREMENT_ID"]);
    EXPECT_EQ(md5Of(packet_status), digest["packet_hash"]["STATUS"]);
    EXPECT_EQ(md5Of(range), scan["RANGE"]);
    EXPECT_EQ(md5Of(reflectivity), scan["REFLECTIVITY"]);
    EXPECT_EQ(md5Of(near_ir), scan["NEAR_IR"]);
    if (scan.contains("SIGNAL")) {
      EXPECT_EQ(md5Of(signal), scan["SIGNAL"]);
    }
  }
}

// ---- metadata that does not describe the capture ---------------------------------------------

TEST(OusterCapture, MetadataOfAnotherSensorIsAClearErrorNamingBothFiles) {
  // Same profile and packet size, different serial number.
  const std::string same_size = test::messageOf<InputError>([] {
    openOusterCapture(ousterData("OS-0-128-U1_v2.3.0_1024x10.pcap"),
                      ousterData("OS-1-128_v2.3.0_1024x10.json"));
  });
  EXPECT_THAT(same_size, ::testing::HasSubstr("OS-0-128-U1_v2.3.0_1024x10.pcap: lidar packets "
                                              "come from sensor serial 122150000150"));
  EXPECT_THAT(same_size, ::testing::HasSubstr("OS-1-128_v2.3.0_1024x10.json describes sensor "
                                              "serial 122201000998"));

  // Different packet size.
  const std::string other_size = test::messageOf<InputError>([] {
    openOusterCapture(ousterData("OS-1-64_1024x10_fw20.pcap"),
                      ousterData("OS-0-128-U1_v2.3.0_1024x10.json"));
  });
  EXPECT_THAT(other_size, ::testing::HasSubstr("OS-1-64_1024x10_fw20.pcap: no lidar packet of the "
                                               "8448 bytes that"));
  EXPECT_THAT(other_size, ::testing::HasSubstr("OS-0-128-U1_v2.3.0_1024x10.json implies"));
  EXPECT_THAT(other_size, ::testing::HasSubstr("port 7502: 64 x 12608 bytes"));

  // Nothing matches at all.
  const std::string nothing = test::messageOf<InputError>([] {
    openOusterCapture(ousterData("imu_zm_no_lidar.pcap"),
                      ousterData("OS-0-128-U1_v2.3.0_1024x10.json"));
  });
  EXPECT_THAT(nothing, ::testing::HasSubstr("imu_zm_no_lidar.pcap: no datagram has the size of "
                                            "the packets that"));
  EXPECT_THAT(nothing, ::testing::HasSubstr("port 7513: 8 x 452 bytes"));
}

}  // namespace
}  // namespace taiga::io::ouster
