#include "run_health.hpp"

#include <fmt/format.h>

#include "taiga/core/log.hpp"

namespace taiga::pipeline {

std::string HealthReport::verdict() const {
  if (trackLost()) return "lost";
  if (lost > 0) return "recovered";
  return degraded > 0 ? "degraded" : "ok";
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

std::string HealthLog::progressNote() const {
  if (report_.stretches.empty() || previous_ == ScanStatus::kOk) {
    if (report_.lost + report_.degraded == 0) return {};
    return fmt::format("{} degraded, {} lost", report_.degraded, report_.lost);
  }
  const HealthStretch& now = report_.stretches.back();
  return fmt::format("{} since {:.1f} s", now.status, now.from_s);
}

}  // namespace taiga::pipeline
