#include "recording_feed.hpp"

#include <algorithm>
#include <variant>

namespace taiga::pipeline {

RecordingFeed::RecordingFeed(io::Recording& recording, Pacing pacing,
                             std::size_t max_queued_scans)
    : pacing_(pacing),
      max_queued_scans_(std::max<std::size_t>(max_queued_scans, 1)),
      reader_([this, &recording] { read(recording); }) {}

RecordingFeed::~RecordingFeed() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  reader_.join();
}

bool RecordingFeed::waitForRoom(std::unique_lock<std::mutex>& lock,
                                const io::RecordingEvent& event, Clock::time_point due) {
  const bool is_scan = std::holds_alternative<io::Scan>(event);
  if (pacing_ == Pacing::kAsFastAsPossible) {
    changed_.wait(lock, [&] { return stopping_ || !is_scan || queued_scans_ < max_queued_scans_; });
    return !stopping_;
  }
  // Sleeps until the event is due, waking early only to stop; then makes room by dropping.
  if (changed_.wait_until(lock, due, [this] { return stopping_; })) return false;
  if (is_scan && queued_scans_ >= max_queued_scans_) {
    const auto oldest = std::find_if(queue_.begin(), queue_.end(), [](const Delivery& d) {
      return std::holds_alternative<io::Scan>(d.event);
    });
    queue_.erase(oldest);
    --queued_scans_;
    ++dropped_scans_;
  }
  return true;
}

void RecordingFeed::read(io::Recording& recording) {
  try {
    const Clock::time_point wall_start = Clock::now();
    std::optional<double> first_event_s;
    while (true) {
      const Clock::time_point read_start = Clock::now();
      std::optional<io::RecordingEvent> event = recording.next();
      if (!event) break;
      const double read_ms =
          std::chrono::duration<double, std::milli>(Clock::now() - read_start).count();
      const double t_event = io::eventTime(*event);
      if (!first_event_s) first_event_s = t_event;
      const Clock::time_point due =
          pacing_ == Pacing::kLive
              ? Clock::now()
              : wall_start + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(t_event - *first_event_s));
      {
        std::unique_lock lock(mutex_);
        if (!waitForRoom(lock, *event, due)) return;
        queued_scans_ += std::holds_alternative<io::Scan>(*event);
        queue_.push_back({std::move(*event), Clock::now(), read_ms});
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

std::optional<RecordingFeed::Delivery> RecordingFeed::next() {
  std::optional<Delivery> delivery;
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return !queue_.empty() || finished_; });
    if (queue_.empty()) {
      if (error_) std::rethrow_exception(error_);
      return std::nullopt;
    }
    delivery = std::move(queue_.front());
    queue_.pop_front();
    queued_scans_ -= std::holds_alternative<io::Scan>(delivery->event);
  }
  changed_.notify_all();  // a reader waiting for room may go on
  return delivery;
}

std::size_t RecordingFeed::droppedScans() const {
  std::lock_guard lock(mutex_);
  return dropped_scans_;
}

}  // namespace taiga::pipeline
