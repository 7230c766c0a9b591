#include "taiga/io/rosbag.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

using ::testing::HasSubstr;
using test::messageOf;

constexpr double kT0 = 1700000000.0;

// A scan whose values survive the bag format exactly: float32 positions, times whole
// nanoseconds after a stamp that is itself whole nanoseconds.
Scan makeScan(std::uint64_t index, double t_start_s, std::uint16_t rows, std::uint16_t columns) {
  Scan scan;
  scan.index = index;
  PointCloud& cloud = scan.cloud_in_lidar;
  for (std::uint16_t col = 0; col < columns; ++col) {
    for (std::uint16_t row = 0; row < rows; ++row) {
      if ((row + col) % 5 == 3) continue;  // no return here
      cloud.positions.emplace_back(float(1.5f + row), float(-0.25f * col), float(0.125f * (row - col)));
      cloud.times_s.push_back(t_start_s + 1e-9 * std::round(1e8 * col / columns));
      cloud.intensities.push_back(float(10 * row + col));
      cloud.rings.push_back(row);
      cloud.columns.push_back(col);
    }
  }
  std::tie(scan.t_start_s, scan.t_end_s) = cloud.timeSpan();
  return scan;
}

ImuSample makeImu(double t_s, double gravity) {
  ImuSample imu;
  imu.t_s = t_s;
  imu.acceleration_imu_mps2 = {0.1, -0.2, gravity};
  imu.angular_velocity_imu_radps = {0.01, 0.02, -0.3};
  return imu;
}

GnssFix makeFix(double t_s) {
  GnssFix fix;
  fix.t_s = t_s;
  fix.latitude_deg = 60.1699;
  fix.longitude_deg = 24.9384;
  fix.height_ellipsoid_m = 35.5;
  fix.covariance_enu_m2 << 0.5, 0.1, 0, 0.1, 0.6, 0, 0, 0, 2.0;
  fix.covariance_type = GnssCovarianceType::kKnown;
  fix.status = GnssStatus::kGbasFix;
  return fix;
}

// Writes 1 s of data: 10 scans, 200 IMU samples, 1 fix.
void writeBag(const std::filesystem::path& path, double gravity, BagCompression compression, bool organized) {
  BagWriter writer(path, compression);
  for (int i = 0; i < 200; ++i) writer.writeImu("/imu", "imu", makeImu(kT0 + 0.005 * i, gravity));
  for (int i = 0; i < 10; ++i) {
    const Scan scan = makeScan(i, kT0 + 0.1 * i, 4, 16);
    writer.writeScan("/points", "os_sensor", scan, organized ? std::optional(ScanGrid{4, 16}) : std::nullopt);
  }
  writer.writeGnss("/fix", "gnss", makeFix(kT0 + 0.5));
}

std::vector<RecordingEvent> readAll(const std::filesystem::path& path, RecordingConfig recording = {}, RigConfig rig = {}) {
  Recording rec(path.string(), openBagStreams(path, recording, rig));
  std::vector<RecordingEvent> events;
  while (auto e = rec.next()) events.push_back(std::move(*e));
  return events;
}

TEST(RosBag, WrittenDataReadsBackIdentically) {
  test::TempDir dir;
  for (bool organized : {false, true}) {
    for (BagCompression compression : {BagCompression::kNone, BagCompression::kLz4, BagCompression::kBz2}) {
      const auto path = dir.file("rec.bag");
      writeBag(path, 9.81, compression, organized);
      const std::vector<RecordingEvent> events = readAll(path);
      std::size_t scans = 0, imus = 0, fixes = 0;
      double previous_t = 0.0;
      for (const RecordingEvent& e : events) {
        EXPECT_GE(eventTime(e), previous_t);  // one stream, in time order
        previous_t = eventTime(e);
        if (const auto* scan = std::get_if<Scan>(&e)) {
          const Scan expected = makeScan(scans, kT0 + 0.1 * scans, 4, 16);
          const PointCloud& got = scan->cloud_in_lidar;
          ASSERT_EQ(got.size(), expected.cloud_in_lidar.size());
          // The organized layout stores points row by row, the flat one in the written order.
          for (std::size_t i = 0; i < got.size(); ++i) {
            std::size_t j = i;
            if (organized) {
              j = std::find_if(expected.cloud_in_lidar.positions.begin(), expected.cloud_in_lidar.positions.end(),
                               [&](const Eigen::Vector3d& p) { return p == got.positions[i]; }) -
                  expected.cloud_in_lidar.positions.begin();
            }
            ASSERT_LT(j, expected.cloud_in_lidar.size());
            EXPECT_EQ(got.positions[i], expected.cloud_in_lidar.positions[j]);
            EXPECT_NEAR(got.times_s[i], expected.cloud_in_lidar.times_s[j], 1e-9);
            EXPECT_EQ(got.intensities[i], expected.cloud_in_lidar.intensities[j]);
            EXPECT_EQ(got.rings[i], expected.cloud_in_lidar.rings[j]);
            if (organized) {
              EXPECT_EQ(got.columns[i], expected.cloud_in_lidar.columns[j]);
            }
          }
          EXPECT_EQ(scan->index, scans);
          EXPECT_NEAR(scan->t_end_s, expected.t_end_s, 1e-9);
          ++scans;
        } else if (const auto* imu = std::get_if<ImuSample>(&e)) {
          const ImuSample expected = makeImu(kT0 + 0.005 * imus, 9.81);
          EXPECT_NEAR(imu->t_s, expected.t_s, 1e-9);
          EXPECT_EQ(imu->acceleration_imu_mps2, expected.acceleration_imu_mps2);
          EXPECT_EQ(imu->angular_velocity_imu_radps, expected.angular_velocity_imu_radps);
          EXPECT_FALSE(imu->orientation.has_value());
          ++imus;
        } else {
          const GnssFix& fix = std::get<GnssFix>(e);
          const GnssFix expected = makeFix(kT0 + 0.5);
          EXPECT_EQ(fix.latitude_deg, expected.latitude_deg);
          EXPECT_EQ(fix.longitude_deg, expected.longitude_deg);
          EXPECT_EQ(fix.height_ellipsoid_m, expected.height_ellipsoid_m);
          EXPECT_EQ(fix.covariance_enu_m2, expected.covariance_enu_m2);
          EXPECT_EQ(fix.covariance_type, expected.covariance_type);
          EXPECT_EQ(fix.status, expected.status);
          ++fixes;
        }
      }
      EXPECT_EQ(scans, 10u);
      EXPECT_EQ(imus, 200u);
      EXPECT_EQ(fixes, 1u);
    }
  }
}

TEST(RosBag, AccelerationInGIsDetectedAndConverted) {
  test::TempDir dir;
  writeBag(dir.file("g.bag"), 1.0, BagCompression::kLz4, false);
  for (const RecordingEvent& e : readAll(dir.file("g.bag"))) {
    if (const auto* imu = std::get_if<ImuSample>(&e)) {
      EXPECT_NEAR(imu->acceleration_imu_mps2.z(), 9.80665, 1e-9);
    }
  }
  RigConfig rig;
  rig.imu_acceleration_unit = AccelerationUnit::kMetersPerSecond2;  // the user says otherwise
  for (const RecordingEvent& e : readAll(dir.file("g.bag"), {}, rig)) {
    if (const auto* imu = std::get_if<ImuSample>(&e)) {
      EXPECT_EQ(imu->acceleration_imu_mps2.z(), 1.0);
    }
  }
}

TEST(RosBag, ListsTopicsWithTypesAndCounts) {
  test::TempDir dir;
  writeBag(dir.file("rec.bag"), 9.81, BagCompression::kLz4, false);
  const std::vector<BagTopicInfo> topics = listBagTopics(dir.file("rec.bag"));
  ASSERT_EQ(topics.size(), 3u);
  EXPECT_EQ(topics[0].topic, "/fix");
  EXPECT_EQ(topics[1].datatype, "sensor_msgs/Imu");
  EXPECT_EQ(topics[1].message_count, 200u);
  EXPECT_EQ(topics[2].datatype, "sensor_msgs/PointCloud2");
  EXPECT_NEAR(topics[2].last_receive_time_s - topics[2].first_receive_time_s, 0.9, 1e-3);
}

TEST(RosBag, TopicSelectionErrorsNameTheKeyAndTheChoices) {
  test::TempDir dir;
  const auto path = dir.file("two.bag");
  {
    BagWriter writer(path);
    writer.writeScan("/front/points", "a", makeScan(0, kT0, 2, 4));
    writer.writeScan("/rear/points", "b", makeScan(0, kT0, 2, 4));
    writer.writeImu("/imu", "imu", makeImu(kT0, 9.8));
  }
  const auto topics = listBagTopics(path);
  EXPECT_THAT(messageOf<InputError>([&] { selectBagTopics(path, topics, {}); }),
              HasSubstr("several sensor_msgs/PointCloud2 topics; choose one with recording.lidar_topic"));
  RecordingConfig config;
  config.lidar_topic = "/rear/points";
  EXPECT_EQ(selectBagTopics(path, topics, config).lidar, "/rear/points");
  config.lidar_topic = "/points";
  EXPECT_THAT(messageOf<InputError>([&] { selectBagTopics(path, topics, config); }),
              HasSubstr("recording.lidar_topic is '/points' but the bag has no such topic"));
  config.lidar_topic = "/imu";
  EXPECT_THAT(messageOf<InputError>([&] { selectBagTopics(path, topics, config); }),
              HasSubstr("recording.lidar_topic: topic '/imu' holds sensor_msgs/Imu, expected sensor_msgs/PointCloud2"));
  config = {};
  config.imu_topic = "/imu_raw";
  config.lidar_topic = "/rear/points";
  EXPECT_THAT(messageOf<InputError>([&] { selectBagTopics(path, topics, config); }),
              HasSubstr("recording.imu_topic is '/imu_raw' but the bag has no such topic"));
}

TEST(RosBag, RealOusterPacketBagListsItsTopics) {
  const std::vector<BagTopicInfo> topics = listBagTopics("../shared/data/ouster/512x10_raw.bag");
  ASSERT_EQ(topics.size(), 3u);
  EXPECT_EQ(topics[0].topic, "/os_node0/imu_packets");
  EXPECT_EQ(topics[0].message_count, 10u);
  EXPECT_EQ(topics[1].topic, "/os_node0/lidar_packets");
  EXPECT_EQ(topics[1].datatype, "ouster_ros/PacketMsg");
  EXPECT_EQ(topics[1].message_count, 32u);
  EXPECT_EQ(topics[2].datatype, "std_msgs/String");
}

TEST(RosBag, BadFilesGiveClearErrors) {
  test::TempDir dir;
  EXPECT_THAT(messageOf<InputError>([&] { listBagTopics(dir.file("none.bag")); }), HasSubstr("none.bag: no such file"));
  const auto text = dir.write("text.bag", "this is not a bag\n");
  EXPECT_THAT(messageOf<InputError>([&] { listBagTopics(text); }), HasSubstr("text.bag: cannot read the bag"));

  // A recording cut short: the index at the end is missing.
  writeBag(dir.file("full.bag"), 9.81, BagCompression::kLz4, false);
  const auto size = std::filesystem::file_size(dir.file("full.bag"));
  std::filesystem::copy_file(dir.file("full.bag"), dir.file("cut.bag"));
  std::filesystem::resize_file(dir.file("cut.bag"), size / 2);
  const std::string cut = messageOf<InputError>([&] { readAll(dir.file("cut.bag")); });
  EXPECT_THAT(cut, HasSubstr("cut.bag: "));

  // Bytes damaged inside a chunk: an error naming the bag, never a crash.
  std::filesystem::copy_file(dir.file("full.bag"), dir.file("damaged.bag"));
  {
    std::fstream f(dir.file("damaged.bag"), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size / 3));
    const std::string garbage(4096, '\x5a');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  const std::string damaged = messageOf<InputError>([&] { readAll(dir.file("damaged.bag")); });
  EXPECT_THAT(damaged, HasSubstr("damaged.bag: "));
}

}  // namespace
}  // namespace taiga::io
