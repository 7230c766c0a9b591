#include "taiga/core/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace taiga {

std::string formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "--:--";
  const auto total = static_cast<long long>(std::llround(seconds));
  const long long hours = total / 3600, minutes = (total / 60) % 60, secs = total % 60;
  if (hours > 0) return fmt::format("{}:{:02}:{:02}", hours, minutes, secs);
  return fmt::format("{}:{:02}", minutes, secs);
}

std::string formatProgressLine(const std::string& label, std::size_t done, std::size_t total,
                               const std::string& unit, double elapsed_s) {
  const double rate = elapsed_s > 0.0 ? static_cast<double>(done) / elapsed_s : 0.0;
  if (total == 0) {  // total unknown: count, rate and elapsed time only
    return fmt::format("{}  {} {}  {:.1f} {}/s  elapsed {}", label, done, unit, rate, unit,
                       formatDuration(elapsed_s));
  }
  const double remaining_s =
      rate > 0.0 && total >= done ? static_cast<double>(total - done) / rate : -1.0;
  const double percent =
      total > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 0.0;
  return fmt::format("{}  {}/{} {}  {:3.0f}%  {:.1f} {}/s  elapsed {}  remaining {}", label, done,
                     total, unit, percent, rate, unit, formatDuration(elapsed_s),
                     formatDuration(remaining_s));
}

Progress::Progress(std::string label, std::size_t total, std::string unit, std::FILE* out)
    : Progress(std::move(label), total, std::move(unit), out, isatty(fileno(out)) == 1) {}

Progress::Progress(std::string label, std::size_t total, std::string unit, std::FILE* out,
                   bool enabled)
    : label_(std::move(label)),
      total_(total),
      unit_(std::move(unit)),
      out_(out),
      enabled_(enabled) {}

Progress::~Progress() { finish(); }

void Progress::update(std::size_t done) {
  done_ = total_ == 0 ? done : std::min(done, total_);  // total 0: unknown
  if (!enabled_ || finished_) return;
  if (Clock::now() - last_draw_ >= std::chrono::milliseconds(200)) draw();
}

void Progress::update(std::size_t done, std::string note) {
  note_ = std::move(note);
  update(done);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (!enabled_) return;
  draw();
  std::fputc('\n', out_);
  std::fflush(out_);
}

void Progress::draw() {
  last_draw_ = Clock::now();
  const double elapsed_s = std::chrono::duration<double>(last_draw_ - start_).count();
  // \r returns to the line start, \033[K clears what a longer previous line left behind.
  std::string line = formatProgressLine(label_, done_, total_, unit_, elapsed_s);
  if (!note_.empty()) line += "  [" + note_ + "]";
  std::fprintf(out_, "\r%s\033[K", line.c_str());
  std::fflush(out_);
}

}  // namespace taiga
