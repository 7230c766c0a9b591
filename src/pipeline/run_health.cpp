#include "run_health.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "taiga/core/log.hpp"
#include "taiga/core/percentile.hpp"

namespace taiga::pipeline {

std::string HealthReport::verdict() const {
  if (trackLost()) return "lost";
  if (calibration_suspect) return "suspect";
  if (lost > 0) return "recovered";
  return degraded > 0 ? "degraded" : "ok";
}

std::vector<std::uint64_t> HealthReport::floatingSegments() const {
  std::vector<std::uint64_t> floating;
  for (std::uint64_t segment = 1; segment < map_segments; ++segment) {
    const bool found = std::any_of(reattached.begin(), reattached.end(),
                                   [&](const Reattachment& r) { return r.segment == segment; });
    if (!found) floating.push_back(segment);
  }
  return floating;
}

void HealthLog::onScan(const ScanOutcome& scan, const lie::SE3& /*T_map_odom*/) {
  const ScanHealth& h = scan.health;
  switch (h.status) {
    case ScanStatus::kOk:
      ++report_.ok;
      break;
    case ScanStatus::kDegraded:
      ++report_.degraded;
      break;
    case ScanStatus::kLost:
      ++report_.lost;
      break;
  }
  report_.map_segments = scan.map_segment + 1;
  if (scan.lidar != LidarFactor::kFirstScan)  // the first scan of a model is not filtered
    points_.emplace_back(scan.t_s, static_cast<double>(scan.source_points));
  const bool with_imu = !scan.imu_rate_poses.empty();
  if (with_imu && scan.lidar == LidarFactor::kUsed) {
    innovations_deg_.push_back(scan.innovation_deg);
    innovations_m_.push_back(scan.innovation_m);
  }
  report_.ended_lost = h.status == ScanStatus::kLost;
  if (h.status != ScanStatus::kOk) {
    if (previous_ == h.status) {
      report_.stretches.back().to_s = scan.t_s;
      ++report_.stretches.back().scans;
    } else {
      report_.stretches.push_back({scanStatusName(h.status), scan.t_s, scan.t_s, 1, h.reason});
    }
  }
  if (h.status == ScanStatus::kLost && previous_ != ScanStatus::kLost)
    logger().warn("track lost at {:.3f} s (scan {}): {}", scan.t_s, scan.scan_index, h.reason);
  if (h.status == ScanStatus::kOk && previous_ == ScanStatus::kLost)
    logger().warn("track recovered at {:.3f} s (scan {}), map segment {}", scan.t_s,
                  scan.scan_index, scan.map_segment);
  if (h.status == ScanStatus::kDegraded)
    logger().debug("scan {} at {:.3f} s degraded: {}", scan.scan_index, scan.t_s, h.reason);
  previous_ = h.status;
}

void HealthLog::findSparseScans() {
  std::vector<double> counts;
  for (const auto& [t_s, n] : points_) counts.push_back(n);
  if (counts.empty()) return;
  const double limit = config_.sparse_scan_ratio * percentile(counts, 50.0);
  bool in_stretch = false;
  for (const auto& [t_s, n] : points_) {
    const bool sparse = n < limit;
    if (sparse && in_stretch) {
      report_.sparse.back().to_s = t_s;
      ++report_.sparse.back().scans;
    } else if (sparse) {
      report_.sparse.push_back({"sparse", t_s, t_s, 1,
                                fmt::format("fewer than {:.0f} points after the voxel filter "
                                            "({:.0f} % of the run's median)",
                                            limit, 100.0 * config_.sparse_scan_ratio)});
    }
    report_.sparse_scans += sparse;
    in_stretch = sparse;
  }
  if (report_.sparse_scans > 0)
    logger().warn(
        "{} scans in {} stretches had fewer than {:.0f} % of the run's median points after the "
        "voxel filter (lost packets or a blocked view), the first from {:.3f} s",
        report_.sparse_scans, report_.sparse.size(), 100.0 * config_.sparse_scan_ratio,
        report_.sparse.front().from_s);
}

HealthReport HealthLog::finish() {
  findSparseScans();
  if (!innovations_deg_.empty()) {
    report_.median_innovation_deg = percentile(innovations_deg_, 50.0);
    report_.median_innovation_m = percentile(innovations_m_, 50.0);
    report_.calibration_suspect = report_.median_innovation_deg > config_.max_median_innovation_deg;
    if (report_.calibration_suspect)
      logger().warn(
          "the IMU's prediction and the registration disagree by {:.2f} deg per scan (median; "
          "above odometry.health.max_median_innovation_deg {:.2f}): the lidar-IMU extrinsic "
          "rotation (rig.T_body_lidar), the time offset (rig.lidar_time_offset_s) or the IMU "
          "noise settings are probably wrong, and the trajectory drifts for it; `taiga calibrate` "
          "or calibration.at_start: true estimates the first two (docs/calibration.md)",
          report_.median_innovation_deg, config_.max_median_innovation_deg);
  }
  return report_;
}

std::string HealthLog::progressNote() const {
  if (report_.stretches.empty() || previous_ == ScanStatus::kOk) {
    if (report_.lost + report_.degraded == 0) return {};
    return fmt::format("{} degraded, {} lost", report_.degraded, report_.lost);
  }
  const HealthStretch& now = report_.stretches.back();
  return fmt::format("{} since {:.1f} s", now.status, now.from_s);
}

}  // namespace taiga::pipeline
