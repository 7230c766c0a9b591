#pragma once
// The health monitor's verdicts as `taiga run` reports them (docs/odometry.md, "Health"): a
// warning on the terminal when the track is lost and when it recovers, the stretches of
// degraded and lost scans, and the status for the progress line. Internal to the pipeline.

#include <optional>
#include <string>
#include <vector>

#include "taiga/pipeline/run.hpp"
#include "taiga/pipeline/slam_system.hpp"

namespace taiga::pipeline {

class HealthLog final : public SlamObserver {
 public:
  explicit HealthLog(const HealthConfig& config) : config_(config) {}
  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;
  /// The report, with the run's innovation statistics.
  HealthReport finish();

  /// For the progress line: empty while ok, else e.g. "lost since 12.3 s".
  std::string progressNote() const;

 private:
  HealthConfig config_;
  HealthReport report_;
  std::vector<double> innovations_deg_, innovations_m_;  ///< used lidar factors, with an IMU
  std::vector<std::pair<double, double>> points_;        ///< each scan's time and source points
  /// The stretches of scans with few points (HealthReport::sparse).
  void findSparseScans();
  std::optional<ScanStatus> previous_;
};

}  // namespace taiga::pipeline
