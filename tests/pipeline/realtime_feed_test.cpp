// The --realtime replay: sensor-rate delivery into a bounded queue that drops the oldest scan
// when the consumer falls behind, never an IMU reading, and passes the reader's errors on.
#include "../../src/pipeline/realtime_feed.hpp"

#include <gtest/gtest.h>

#include <thread>

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

TEST(RealtimeFeed, ASlowConsumerLosesTheOldestScansButNoImuReading) {
  io::Recording recording = fakeRecording(1.0);  // 11 scans, 101 IMU readings in 1 s
  RealtimeFeed feed(recording, 2);
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

TEST(RealtimeFeed, DeliversAtSensorRate) {
  io::Recording recording = fakeRecording(0.5);
  const auto start = RealtimeFeed::Clock::now();
  RealtimeFeed feed(recording, 2);
  int events = 0;
  while (feed.next()) ++events;
  const double elapsed_s =
      std::chrono::duration<double>(RealtimeFeed::Clock::now() - start).count();
  EXPECT_EQ(events, 6 + 51);
  EXPECT_GE(elapsed_s, 0.5);  // the last event is due 0.5 s after the first
  EXPECT_EQ(feed.droppedScans(), 0u);
}

TEST(RealtimeFeed, PassesTheReadersErrorOnAfterWhatItDelivered) {
  io::Recording recording = fakeRecording(1.0, 3);
  RealtimeFeed feed(recording, 2);
  int scans = 0;
  try {
    while (auto delivery = feed.next()) scans += std::holds_alternative<io::Scan>(delivery->event);
    FAIL() << "the reader's error was lost";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "fake.bag: truncated");
  }
  EXPECT_EQ(scans, 3);
}

TEST(RealtimeFeed, StopsCleanlyWhenLeftEarly) {
  io::Recording recording = fakeRecording(30.0);
  const auto start = RealtimeFeed::Clock::now();
  {
    RealtimeFeed feed(recording, 2);
    ASSERT_TRUE(feed.next());
  }  // the destructor must not wait for the 30 s replay
  EXPECT_LT(std::chrono::duration<double>(RealtimeFeed::Clock::now() - start).count(), 5.0);
}

}  // namespace
}  // namespace taiga::pipeline
