// The reader thread of taiga run: at sensor rate (--realtime) into a bounded queue that drops the
// oldest scan when the consumer falls behind, never an IMU reading; as fast as possible without
// dropping anything; and in both, the reader's errors passed on.
#include "../../src/pipeline/recording_feed.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <thread>
#include <vector>

#include "taiga/core/errors.hpp"

namespace taiga::pipeline {
namespace {

// A stream of scans at 10 Hz and IMU readings at 100 Hz over `duration_s`, optionally failing
// after `fail_after` events.
class FakeStream final : public io::StreamSource {
 public:
  FakeStream(bool scans, double duration_s, int fail_after = -1)
      : scans_(scans), duration_s_(duration_s), fail_after_(fail_after) {}
  std::string name() const override { return scans_ ? "lidar" : "imu"; }
  std::optional<io::RecordingEvent> next() override {
    if (emitted_ == fail_after_) throw InputError("fake.bag: truncated");
    const double t = 100.0 + emitted_ * (scans_ ? 0.1 : 0.01);
    if (t > 100.0 + duration_s_) return std::nullopt;
    ++emitted_;
    if (!scans_) return ImuSample{.t_s = t};
    io::Scan scan;
    scan.index = static_cast<std::uint64_t>(emitted_ - 1);
    scan.t_start_s = t - 0.1;
    scan.t_end_s = t;
    return scan;
  }

 private:
  bool scans_;
  double duration_s_;
  int fail_after_;
  int emitted_ = 0;
};

io::Recording fakeRecording(double duration_s, int lidar_fail_after = -1) {
  std::vector<std::unique_ptr<io::StreamSource>> streams;
  streams.push_back(std::make_unique<FakeStream>(true, duration_s, lidar_fail_after));
  streams.push_back(std::make_unique<FakeStream>(false, duration_s));
  return io::Recording("fake.bag", std::move(streams));
}

TEST(RecordingFeed, ASlowConsumerLosesTheOldestScansButNoImuReading) {
  io::Recording recording = fakeRecording(1.0);  // 11 scans, 101 IMU readings in 1 s
  RecordingFeed feed(recording, RecordingFeed::Pacing::kSensorRate, 2);
  int scans = 0, imu = 0;
  std::uint64_t last_index = 0;
  while (auto delivery = feed.next()) {
    if (const auto* scan = std::get_if<io::Scan>(&delivery->event)) {
      if (scans > 0) {
        EXPECT_GT(scan->index, last_index);  // order kept
      }
      last_index = scan->index;
      ++scans;
      // 250 ms per scan against one every 100 ms: the queue overflows.
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    } else {
      ++imu;
    }
  }
  EXPECT_EQ(imu, 101);
  EXPECT_GE(feed.droppedScans(), 1u);
  EXPECT_EQ(static_cast<std::size_t>(scans) + feed.droppedScans(), 11u);
  EXPECT_EQ(last_index, 10u);  // the newest scan is never the one dropped
}

TEST(RecordingFeed, DeliversAtSensorRate) {
  io::Recording recording = fakeRecording(0.5);
  const auto start = RecordingFeed::Clock::now();
  RecordingFeed feed(recording, RecordingFeed::Pacing::kSensorRate, 2);
  int events = 0;
  while (feed.next()) ++events;
  const double elapsed_s =
      std::chrono::duration<double>(RecordingFeed::Clock::now() - start).count();
  EXPECT_EQ(events, 6 + 51);
  EXPECT_GE(elapsed_s, 0.5);  // the last event is due 0.5 s after the first
  EXPECT_EQ(feed.droppedScans(), 0u);
}

TEST(RecordingFeed, PassesTheReadersErrorOnAfterWhatItDelivered) {
  io::Recording recording = fakeRecording(1.0, 3);
  RecordingFeed feed(recording, RecordingFeed::Pacing::kSensorRate, 2);
  int scans = 0;
  try {
    while (auto delivery = feed.next()) scans += std::holds_alternative<io::Scan>(delivery->event);
    FAIL() << "the reader's error was lost";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "fake.bag: truncated");
  }
  EXPECT_EQ(scans, 3);
}

TEST(RecordingFeed, StopsCleanlyWhenLeftEarly) {
  io::Recording recording = fakeRecording(30.0);
  const auto start = RecordingFeed::Clock::now();
  {
    RecordingFeed feed(recording, RecordingFeed::Pacing::kSensorRate, 2);
    ASSERT_TRUE(feed.next());
  }  // the destructor must not wait for the 30 s replay
  EXPECT_LT(std::chrono::duration<double>(RecordingFeed::Clock::now() - start).count(), 5.0);
}

TEST(RecordingFeed, AsFastAsPossibleDeliversEveryEventInOrderToASlowConsumer) {
  io::Recording recording = fakeRecording(1.0);  // 11 scans, 101 IMU readings in 1 s
  const auto start = RecordingFeed::Clock::now();
  RecordingFeed feed(recording, RecordingFeed::Pacing::kAsFastAsPossible, 2);
  std::vector<double> times;
  int scans = 0;
  while (auto delivery = feed.next()) {
    times.push_back(io::eventTime(delivery->event));
    EXPECT_GE(delivery->read_ms, 0.0);
    if (std::holds_alternative<io::Scan>(delivery->event) && ++scans <= 3) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the reader must wait, not drop
    }
  }
  EXPECT_EQ(scans, 11);
  EXPECT_EQ(times.size(), 11u + 101u);
  EXPECT_TRUE(std::is_sorted(times.begin(), times.end()));
  EXPECT_EQ(feed.droppedScans(), 0u);
  // Not paced: the 1 s recording is through in the consumer's 150 ms plus reading.
  EXPECT_LT(std::chrono::duration<double>(RecordingFeed::Clock::now() - start).count(), 0.9);
}

TEST(RecordingFeed, AsFastAsPossiblePassesTheReadersErrorOn) {
  io::Recording recording = fakeRecording(1.0, 3);
  RecordingFeed feed(recording, RecordingFeed::Pacing::kAsFastAsPossible, 1);
  int scans = 0;
  EXPECT_THROW(
      while (auto delivery = feed.next()) scans += std::holds_alternative<io::Scan>(delivery->event),
      InputError);
  EXPECT_EQ(scans, 3);
}

TEST(RecordingFeed, StopsCleanlyWhenLeftEarlyWithAFullQueue) {
  io::Recording recording = fakeRecording(30.0);
  RecordingFeed feed(recording, RecordingFeed::Pacing::kAsFastAsPossible, 1);
  ASSERT_TRUE(feed.next());
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the reader fills the queue
}  // the destructor must wake the waiting reader, or this test hangs

}  // namespace
}  // namespace taiga::pipeline
