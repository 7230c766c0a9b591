#pragma once
// The APE split by the health status `taiga run` gave each scan (scans.csv, docs/odometry.md
// "Health"): how far off the poses the run called ok were, apart from those it flagged. A run
// that fails silently shows up as a large error among the ok poses.

#include <filesystem>
#include <string>
#include <vector>

#include "taiga/eval/evaluate.hpp"

namespace taiga::eval {

/// One scan's status, at the scan's time (its end, as the trajectories are stamped).
struct ScanStatusAt {
  double t_s = 0.0;
  std::string status;
};

/// The t_s and status columns of a run's scans.csv, in time order. InputError naming the file
/// (and line) when it cannot be read or lacks a column.
std::vector<ScanStatusAt> readScanStatuses(const std::filesystem::path& scans_csv);

struct StatusApe {
  std::string status;
  std::size_t poses = 0;
  double rmse_m = 0.0, max_m = 0.0;
};

/// The APE translation errors of `result`, grouped by the status of the scan each estimated
/// pose belongs to: the first scan ending at or after the pose (scan-rate poses are at scan
/// ends, IMU-rate poses lead up to them). Poses after the last scan are left out. In the order
/// ok, degraded, lost; statuses without poses are omitted.
std::vector<StatusApe> apeByStatus(const EvalResult& result,
                                   const std::vector<ScanStatusAt>& scans);

/// The poses of `estimate` whose scan (as above) has `status`: e.g. the ok ones, to evaluate
/// where the run says it was on track with an alignment of their own (the lost poses of a long
/// stretch otherwise pull the alignment of all poses, and the ok ones look worse than they are).
Trajectory posesWithStatus(const Trajectory& estimate, const std::vector<ScanStatusAt>& scans,
                           const std::string& status);

}  // namespace taiga::eval
