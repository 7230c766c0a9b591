#pragma once
// Replays a recording at sensor rate on its own thread, as a live driver would deliver it, into
// a bounded queue. When the odometry falls behind by more than `max_queued_scans` scans, the
// oldest waiting scan is dropped; IMU readings never are (they are small, and the
// preintegration needs every one). Internal to the pipeline module (taiga run --realtime).

#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "taiga/io/recording.hpp"

namespace taiga::pipeline {

class RealtimeFeed {
 public:
  using Clock = std::chrono::steady_clock;
  struct Delivery {
    io::RecordingEvent event;
    Clock::time_point delivered;  ///< when a live sensor would have handed the event over
  };

  /// Starts replaying; `recording` must outlive the feed.
  RealtimeFeed(io::Recording& recording, std::size_t max_queued_scans);
  ~RealtimeFeed();
  RealtimeFeed(const RealtimeFeed&) = delete;
  RealtimeFeed& operator=(const RealtimeFeed&) = delete;

  /// The next event, waiting for it; nothing at the end. Rethrows what the reader threw.
  std::optional<Delivery> next();
  std::size_t droppedScans() const;

 private:
  void replay(io::Recording& recording);

  const std::size_t max_queued_scans_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Delivery> queue_;
  std::size_t queued_scans_ = 0;
  std::size_t dropped_scans_ = 0;
  bool finished_ = false;
  bool stopping_ = false;
  std::exception_ptr error_;
  std::thread reader_;
};

}  // namespace taiga::pipeline
