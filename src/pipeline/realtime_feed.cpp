#include "realtime_feed.hpp"

#include <algorithm>
#include <variant>

namespace taiga::pipeline {

RealtimeFeed::RealtimeFeed(io::Recording& recording, std::size_t max_queued_scans)
    : max_queued_scans_(std::max<std::size_t>(max_queued_scans, 1)),
      reader_([this, &recording] { replay(recording); }) {}

RealtimeFeed::~RealtimeFeed() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  reader_.join();
}

void RealtimeFeed::replay(io::Recording& recording) {
  try {
    const Clock::time_point wall_start = Clock::now();
    std::optional<double> first_event_s;
    while (std::optional<io::RecordingEvent> event = recording.next()) {
      const double t_event = io::eventTime(*event);
      if (!first_event_s) first_event_s = t_event;
      const Clock::time_point due =
          wall_start + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(t_event - *first_event_s));
      {
        std::unique_lock lock(mutex_);
        // Sleeps until the event is due, waking early only to stop.
        if (changed_.wait_until(lock, due, [this] { return stopping_; })) return;
        const bool is_scan = std::holds_alternative<io::Scan>(*event);
        if (is_scan && queued_scans_ >= max_queued_scans_) {
          const auto oldest = std::find_if(queue_.begin(), queue_.end(), [](const Delivery& d) {
            return std::holds_alternative<io::Scan>(d.event);
          });
          queue_.erase(oldest);
          --queued_scans_;
          ++dropped_scans_;
        }
        queue_.push_back({std::move(*event), Clock::now()});
        queued_scans_ += is_scan;
      }
      changed_.notify_all();
    }
  } catch (...) {
    std::lock_guard lock(mutex_);
    error_ = std::current_exception();
  }
  {
    std::lock_guard lock(mutex_);
    finished_ = true;
  }
  changed_.notify_all();
}

std::optional<RealtimeFeed::Delivery> RealtimeFeed::next() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return !queue_.empty() || finished_; });
  if (queue_.empty()) {
    if (error_) std::rethrow_exception(error_);
    return std::nullopt;
  }
  Delivery delivery = std::move(queue_.front());
  queue_.pop_front();
  queued_scans_ -= std::holds_alternative<io::Scan>(delivery.event);
  return delivery;
}

std::size_t RealtimeFeed::droppedScans() const {
  std::lock_guard lock(mutex_);
  return dropped_scans_;
}

}  // namespace taiga::pipeline
