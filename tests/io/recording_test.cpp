#include "taiga/io/recording.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <deque>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

using ::testing::HasSubstr;
using test::messageOf;

class ListStream final : public StreamSource {
 public:
  ListStream(std::string name, std::deque<RecordingEvent> events) : name_(std::move(name)), events_(std::move(events)) {}
  std::string name() const override { return name_; }
  std::optional<RecordingEvent> next() override {
    if (events_.empty()) return std::nullopt;
    RecordingEvent e = std::move(events_.front());
    events_.pop_front();
    return e;
  }

 private:
  std::string name_;
  std::deque<RecordingEvent> events_;
};

ImuSample imuAt(double t) {
  ImuSample s;
  s.t_s = t;
  return s;
}

Scan scanFrom(double t_start, double t_end) {
  Scan scan;
  scan.t_start_s = t_start;
  scan.t_end_s = t_end;
  scan.cloud_in_lidar.positions = {{1, 0, 0}, {0, 1, 0}};
  scan.cloud_in_lidar.times_s = {t_start, t_end};
  return scan;
}

std::vector<double> times(Recording& recording) {
  std::vector<double> out;
  while (auto e = recording.next()) out.push_back(eventTime(*e));
  return out;
}

Recording make(std::deque<RecordingEvent> lidar, std::deque<RecordingEvent> imu, double offset_s = 0.0) {
  std::vector<std::unique_ptr<StreamSource>> streams;
  streams.push_back(std::make_unique<ListStream>("lidar", std::move(lidar)));
  streams.push_back(std::make_unique<ListStream>("imu", std::move(imu)));
  return Recording("test", std::move(streams), offset_s);
}

TEST(Recording, MergesStreamsByEventTimeWithScansAtTheirEnd) {
  Recording recording = make({scanFrom(0.0, 0.1), scanFrom(0.1, 0.2)}, {imuAt(0.0), imuAt(0.05), imuAt(0.1), imuAt(0.15)});
  // Ties (the scan ending at 0.1 and the sample at 0.1) go to the stream listed first.
  EXPECT_EQ(times(recording), (std::vector<double>{0.0, 0.05, 0.1, 0.1, 0.15, 0.2}));
}

TEST(Recording, AppliesTheLidarClockOffsetToEveryScanTime) {
  Recording recording = make({scanFrom(0.0, 0.1)}, {imuAt(0.0), imuAt(0.12)}, 0.03);
  std::optional<RecordingEvent> e;
  while ((e = recording.next()) && !std::holds_alternative<Scan>(*e)) {
  }
  ASSERT_TRUE(e.has_value());
  const Scan& scan = std::get<Scan>(*e);
  EXPECT_DOUBLE_EQ(scan.t_start_s, 0.03);
  EXPECT_DOUBLE_EQ(scan.t_end_s, 0.13);
  EXPECT_DOUBLE_EQ(scan.cloud_in_lidar.times_s[1], 0.13);
  EXPECT_FALSE(recording.next().has_value());  // the sample at 0.12 s came before the shifted scan
}

TEST(Recording, TakesTheGyrosScaleAndAxisErrorsOutOfItsReadings) {
  GyroAxes axes;
  axes.M_reading_true << 1.02, 0.01, 0.0, 0.0, 0.98, 0.0, 0.005, 0.0, 1.0;
  const Eigen::Vector3d rate_radps(0.3, -1.2, 0.7);
  ImuSample reading = imuAt(0.0);
  reading.angular_velocity_imu_radps = axes.M_reading_true * rate_radps;
  reading.acceleration_imu_mps2 = {0.1, 0.2, 9.8};
  Recording recording = make({}, {reading});
  recording.setGyroAxes(axes);
  const std::optional<RecordingEvent> e = recording.next();
  ASSERT_TRUE(e && std::holds_alternative<ImuSample>(*e));
  const ImuSample& corrected = std::get<ImuSample>(*e);
  EXPECT_TRUE(corrected.angular_velocity_imu_radps.isApprox(rate_radps, 1e-12));
  EXPECT_EQ(corrected.acceleration_imu_mps2, reading.acceleration_imu_mps2);  // the gyro's only
}

TEST(Recording, DropsRepeatedOrSlightlyEarlierEventsAndCountsThem) {
  Recording recording = make({}, {imuAt(1.0), imuAt(1.0), imuAt(0.9), imuAt(1.1)});
  EXPECT_EQ(times(recording), (std::vector<double>{1.0, 1.1}));
  EXPECT_EQ(recording.repairs().out_of_order_dropped, 2u);
}

TEST(Recording, RejectsAClockThatJumpsBack) {
  Recording recording = make({}, {imuAt(100.0), imuAt(100.1), imuAt(3.0)});
  EXPECT_THAT(messageOf<InputError>([&] { times(recording); }),
              HasSubstr("test: imu: time jumps back by 97.100 s (from 100.100000 to 3.000000 s)"));
}

}  // namespace
}  // namespace taiga::io
