#pragma once
// Georeferencing in taiga run (issue 9). GnssRecorder observes the SLAM system: it keeps the
// fixes (and the IMU's absolute orientation, which only the pf6 fit uses) and georeferences each
// scan's pose as it is published with the fixes received so far (georef/online.hpp). At the end,
// georeferenceRun fits the corrected trajectory to the fixes with the config's georef method
// (georef::georeference) and writes the trajectory and the map in the projected CRS under
// RUN/georef/. Fixes that cannot georeference the run (all gated, too few overlapping the
// trajectory) leave every other output intact: the report says why. Internal to the pipeline.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "taiga/core/system_config.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/georef/georef_files.hpp"
#include "taiga/georef/online.hpp"
#include "taiga/lie/se3.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/pipeline/run.hpp"
#include "taiga/pipeline/slam_system.hpp"

namespace taiga::pipeline {

struct RunMap {
  const mapping::KeyframeStore& store;
  const std::vector<lie::SE3>& poses_T_map_body;
  double voxel_m = 0.0;
};

/// `trajectory`: T_map_body, corrected by the mapping graph.
GeorefRunReport georeferenceRun(const Trajectory& trajectory, const georef::GnssInput& gnss,
                                const SystemConfig& config, const std::string& recording_name,
                                const RunMap& map, const std::filesystem::path& out_dir);

class GnssRecorder final : public SlamObserver {
 public:
  /// A scan's pose in the grid as the online georeferencer gave it when the scan was published.
  struct OnlineGridPose {
    georef::GridPose pose;
    Eigen::Matrix<double, 6, 1> sigma;  ///< of the estimate then: east, north, up, roll, pitch, yaw
    std::size_t fixes = 0;              ///< fixes the estimate used
  };

  explicit GnssRecorder(const SystemConfig& config);

  void onImu(const ImuSample& sample) override;
  void onGnssFix(const GnssFix& fix) override;
  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;

  const georef::GnssInput& input() const { return gnss_; }
  int epsg() const { return config_.epsg; }
  /// The scan at `t_s` in the grid, if it was the last one published and the online
  /// georeference had an estimate for it.
  const OnlineGridPose* onlinePoseAt(double t_s) const {
    return !online_poses_.empty() && online_poses_.back().pose.t_s == t_s ? &online_poses_.back()
                                                                          : nullptr;
  }
  /// DIR/trajectory_online_epsgNNNN.csv: one row per scan from the first online estimate on;
  /// nothing when there was none.
  void writeOnline(const std::filesystem::path& dir) const;

 private:
  GeorefConfig config_;
  bool keep_imu_orientation_;
  georef::GnssInput gnss_{.from_recording = true};
  std::optional<georef::OnlineGeoreferencer> online_;
  std::vector<OnlineGridPose> online_poses_;
};

}  // namespace taiga::pipeline
