#include "taiga/pipeline/clock_tracker.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"

namespace taiga::pipeline {
namespace {

/// The window's grid spans this much around the offset in use: a clock 50 ppm off moves it by
/// 0.5 ms per window, and a grid of +-200 ms (taiga calibrate's) would cost 20 times as much.
/// An offset further off is not found here: that is calibration.at_start's job.
constexpr double kMaxOffsetChange_s = 0.01;
/// The drift line takes the windows of this much time before the present (a crystal's rate
/// changes with its temperature over minutes).
constexpr double kDriftSpan_s = 300.0;

double weight(const ClockWindow& w) { return 1.0 / std::max(w.sigma_s * w.sigma_s, 1e-12); }

/// Weighted least squares line through the windows' estimates (weights 1 / sigma^2). Windows
/// overlap (window_s / every_s of them share each scan), so the slope's formal 1-sigma is
/// widened by the square root of that overlap.
std::optional<ClockLine> fitLine(const std::vector<const ClockWindow*>& windows, double overlap) {
  double sw = 0.0, st = 0.0, sy = 0.0;
  for (const ClockWindow* w : windows) {
    sw += weight(*w);
    st += weight(*w) * w->t_s;
    sy += weight(*w) * w->estimate_s;
  }
  ClockLine line{.t_mean_s = st / sw, .value_s = sy / sw};
  double stt = 0.0, sty = 0.0;
  for (const ClockWindow* w : windows) {
    stt += weight(*w) * (w->t_s - line.t_mean_s) * (w->t_s - line.t_mean_s);
    sty += weight(*w) * (w->t_s - line.t_mean_s) * (w->estimate_s - line.value_s);
  }
  if (!(stt > 0.0)) return std::nullopt;
  line.slope = sty / stt;
  line.slope_sigma = std::sqrt(std::max(overlap, 1.0) / stt);
  return line;
}

/// A drift line needs three windows whose middles span two re-estimates at least.
bool spanEnough(const std::vector<const ClockWindow*>& windows, double every_s) {
  return windows.size() >= 3 && windows.back()->t_s - windows.front()->t_s >= 2.0 * every_s - 1e-6;
}

}  // namespace

ClockTracker::ClockTracker(const CalibrationConfig& config, const RigConfig& rig,
                           std::function<void(double)> set_offset_s)
    : config_(config),
      R_body_imu_(rig.T_body_imu.rotation().matrix()),
      set_offset_s_(std::move(set_offset_s)),
      applied_s_(rig.lidar_time_offset_s) {}

void ClockTracker::adjust(io::Scan& scan) {
  if (pending_ && scan.index >= pending_->apply_at_scan) apply();
  if (drift_line_) {  // between windows the offset follows the line, scan by scan
    const double t_s = scan.t_end_s - scan.lidar_time_offset_s + applied_s_;
    applied_s_ = drift_line_->value_s + drift_line_->slope * (t_s - drift_line_->t_mean_s);
    set_offset_s_(applied_s_);
  }
  io::shiftScanTimes(scan, applied_s_ - scan.lidar_time_offset_s);
  scan_offsets_.emplace_back(scan.index, applied_s_);
  if (!first_scan_s_) {
    first_scan_s_ = scan.t_end_s;
    report_.offset_first_s = applied_s_;
  }
  report_.offset_last_s = applied_s_;
}

void ClockTracker::onImu(const ImuSample& sample) {
  gyro_.push_back({sample.t_s, R_body_imu_ * sample.angular_velocity_imu_radps});
}

double ClockTracker::offsetOf(std::uint64_t scan_index) const {
  for (const auto& [index, offset_s] : scan_offsets_)
    if (index == scan_index) return offset_s;
  return applied_s_;  // not adjusted here (a test's outcome without its scan)
}

void ClockTracker::onScan(const ScanOutcome& scan, const lie::SE3& /*T_map_odom*/) {
  // The increment's two scans may have had different offsets: each goes back to the lidar's
  // clock with its own.
  const std::optional<calib::RotationIncrement> increment = take_.take(scan);
  if (increment)
    increments_.push_back({increment->t0_s - offsetOf(scan.scan_index - 1),
                           increment->t1_s - offsetOf(scan.scan_index), increment->theta_body_rad});
  while (!scan_offsets_.empty() && scan_offsets_.front().first + 1 < scan.scan_index)
    scan_offsets_.pop_front();

  const double t_s = scan.t_s;
  if (!first_scan_s_) first_scan_s_ = t_s;
  if (!last_estimate_s_)
    last_estimate_s_ = *first_scan_s_ + config_.track_window_s - config_.track_every_s;
  if (!pending_ && t_s - *last_estimate_s_ >= config_.track_every_s) {
    last_estimate_s_ = t_s;
    start(t_s, scan.scan_index);
  }
  trim(t_s);
}

void ClockTracker::trim(double t_now_s) {
  const double keep_from_s = t_now_s - config_.track_window_s - kMaxOffsetChange_s - 1.0;
  while (!gyro_.empty() && gyro_.front().t_s < keep_from_s) gyro_.pop_front();
  while (!increments_.empty() && increments_.front().t0_lidar_s + applied_s_ < keep_from_s)
    increments_.pop_front();
}

void ClockTracker::start(double t_now_s, std::uint64_t scan_index) {
  const ClockWindow window{.t_s = t_now_s - 0.5 * config_.track_window_s,
                           .estimate_s = applied_s_,
                           .applied_s = applied_s_};
  std::vector<calib::RotationIncrement> increments;
  for (const LidarIncrement& i : increments_)
    if (i.t0_lidar_s + applied_s_ >= t_now_s - config_.track_window_s)
      increments.push_back(
          {i.t0_lidar_s + applied_s_, i.t1_lidar_s + applied_s_, i.theta_body_rad});
  const calib::TimeRotationOptions options{
      .max_offset_s = kMaxOffsetChange_s,
      .max_offset_sigma_s = config_.max_offset_sigma_s,
      .max_rotation_sigma_rad = config_.max_rotation_sigma_deg * kRadPerDeg};
  auto estimate = [window, options, increments = std::move(increments),
                   gyro = std::vector<calib::GyroReading>(gyro_.begin(), gyro_.end())]() mutable {
    ClockWindow w = window;
    w.increments = increments.size();
    try {
      const calib::TimeRotationEstimate e = calib::estimateTimeRotation(increments, gyro, options);
      w.observable = e.offset_observable;
      w.sigma_s = e.offset_sigma_s;
      w.rotation_change_deg = e.R_correction.angle() * kDegPerRad;
      if (e.offset_observable) w.estimate_s += e.offset_s;
    } catch (const InputError& e) {
      w.failed = e.what();
    }
    return w;
  };
  pending_.emplace(Pending{.apply_at_scan = scan_index + kApplyAfterScans,
                           .result = std::async(std::launch::async, std::move(estimate))});
}

void ClockTracker::apply() {
  ClockWindow w = pending_->result.get();
  pending_.reset();
  if (!w.observable) {
    ++report_.held;
    report_.windows.push_back(w);
    return;
  }
  report_.windows.push_back(w);
  const double t_now_s = w.t_s + 0.5 * config_.track_window_s;
  drift_line_ = driftLine(t_now_s);
  applied_s_ = drift_line_
                   ? drift_line_->value_s + drift_line_->slope * (t_now_s - drift_line_->t_mean_s)
                   : w.estimate_s;
  report_.windows.back().applied_s = applied_s_;
  set_offset_s_(applied_s_);
}

std::optional<ClockLine> ClockTracker::driftLine(double t_s) const {
  std::vector<const ClockWindow*> recent;
  for (const ClockWindow& w : report_.windows)
    if (w.observable && w.t_s >= t_s - kDriftSpan_s) recent.push_back(&w);
  if (!spanEnough(recent, config_.track_every_s)) return std::nullopt;
  const std::optional<ClockLine> line =
      fitLine(recent, config_.track_window_s / config_.track_every_s);
  if (!line || std::abs(line->slope) < 2.0 * line->slope_sigma) return std::nullopt;
  return line;
}

ClockTrackingReport ClockTracker::finish() {
  if (pending_) apply();
  std::vector<const ClockWindow*> observable;
  for (const ClockWindow& w : report_.windows)
    if (w.observable) observable.push_back(&w);
  if (spanEnough(observable, config_.track_every_s)) {
    if (const std::optional<ClockLine> line =
            fitLine(observable, config_.track_window_s / config_.track_every_s)) {
      report_.drift_ppm = 1e6 * line->slope;
      report_.drift_sigma_ppm = 1e6 * line->slope_sigma;
    }
  }
  const std::size_t n = report_.windows.size();
  if (n == 0) {
    report_.text =
        fmt::format("time offset held at {:.2f} ms: the run is shorter than one window of {:.0f} s",
                    1e3 * report_.offset_first_s, config_.track_window_s);
  } else {
    report_.text = fmt::format(
        "time offset followed from {:.2f} to {:.2f} ms over {} windows of {:.0f} s ({} held: "
        "their motion did not show an offset within {:.0f} ms of the one in use)",
        1e3 * report_.offset_first_s, 1e3 * report_.offset_last_s, n, config_.track_window_s,
        report_.held, 1e3 * kMaxOffsetChange_s);
    if (report_.drift_ppm)
      report_.text += fmt::format(
          "; the lidar clock drifts {:+.1f} ppm (1-sigma {:.1f}) against "
          "the IMU's",
          *report_.drift_ppm, *report_.drift_sigma_ppm);
  }
  return report_;
}

}  // namespace taiga::pipeline
