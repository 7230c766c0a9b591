#pragma once
// A progress line for long runs: done/total, rate, elapsed and remaining time, redrawn in place
// at most a few times per second. It draws only on a terminal, so logs and pipes stay clean.

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace taiga {

/// "label  120/3000 scans   4%  9.8 scans/s  elapsed 0:12  remaining 4:54"; with total 0
/// (unknown) "label  120 scans  9.8 scans/s  elapsed 0:12".
std::string formatProgressLine(const std::string& label, std::size_t done, std::size_t total,
                               const std::string& unit, double elapsed_s);

/// "1:02:03" or "4:05"; "--:--" when unknown (negative or non-finite).
std::string formatDuration(double seconds);

class Progress {
 public:
  /// Draws on `out` only when it is a terminal.
  Progress(std::string label, std::size_t total, std::string unit = "scans",
           std::FILE* out = stderr);
  /// Draws on `out` exactly when `enabled` is true (for tests and explicit control).
  Progress(std::string label, std::size_t total, std::string unit, std::FILE* out, bool enabled);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Reports `done` items finished; redraws when 0.2 s have passed since the last redraw.
  void update(std::size_t done);
  /// The same, with a note shown after the counts (e.g. "lost since 12.3 s"); empty: none.
  void update(std::size_t done, std::string note);
  /// Draws the final state and ends the line. Called by the destructor if not before.
  void finish();
  bool enabled() const { return enabled_; }

 private:
  void draw();

  using Clock = std::chrono::steady_clock;
  std::string label_;
  std::size_t total_;
  std::string unit_;
  std::FILE* out_;
  bool enabled_;
  bool finished_ = false;
  std::size_t done_ = 0;
  std::string note_;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_draw_{};
};

}  // namespace taiga
