#pragma once
// Reads a recording on its own thread into a bounded queue, so that reading and decoding (bag
// chunk decompression, point unpacking: 7-8 ms per OS0-128 scan) overlap with the odometry.
//
// Two pacings:
// - kAsFastAsPossible (taiga run): the reader runs ahead by at most `max_queued_scans` scans and
//   then waits; nothing is dropped, so the events and their order are those of the recording.
// - kSensorRate (taiga run --realtime): events are handed over when a live sensor would deliver
//   them; when the odometry falls behind by more than `max_queued_scans` scans, the oldest
//   waiting scan is dropped. IMU readings never are (they are small, and the preintegration
//   needs every one).
// - kLive (taiga run --live): the recording is a live sensor that delivers at its own pace;
//   events are handed over as they come, with kSensorRate's dropping.
// Internal to the pipeline module.

#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "taiga/io/recording.hpp"

namespace taiga::pipeline {

class RecordingFeed {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Pacing { kAsFastAsPossible, kSensorRate, kLive };
  struct Delivery {
    io::RecordingEvent event;
    Clock::time_point delivered;  ///< when the event entered the queue
    double read_ms = 0.0;         ///< the reader's time to read and decode this event
  };

  /// Starts reading; `recording` must outlive the feed.
  RecordingFeed(io::Recording& recording, Pacing pacing, std::size_t max_queued_scans);
  ~RecordingFeed();
  RecordingFeed(const RecordingFeed&) = delete;
  RecordingFeed& operator=(const RecordingFeed&) = delete;

  /// The next event, waiting for it; nothing at the end. Rethrows what the reader threw.
  std::optional<Delivery> next();
  /// Scans dropped because the queue was full (kSensorRate and kLive).
  std::size_t droppedScans() const;

 private:
  void read(io::Recording& recording);
  /// Waits, with the lock held, until `event` may be queued; false when stopping.
  bool waitForRoom(std::unique_lock<std::mutex>& lock, const io::RecordingEvent& event,
                   Clock::time_point due);

  const Pacing pacing_;
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
