#pragma once
// Georeferencing at the end of taiga run (issue 9): with GNSS fixes in the recording, the
// corrected trajectory is fitted to them with the config's georef method
// (georef::georeference), and the trajectory and the map are written in the projected CRS under
// RUN/georef/. Fixes that cannot georeference the run (all gated, too few overlapping the
// trajectory) leave every other output intact: the report says why. Internal to the pipeline.

#include <filesystem>
#include <string>
#include <vector>

#include "taiga/core/system_config.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/georef/georef_files.hpp"
#include "taiga/georef/online.hpp"
#include "taiga/lie/se3.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/pipeline/run.hpp"

namespace taiga::pipeline {

struct RunMap {
  const mapping::KeyframeStore& store;
  const std::vector<lie::SE3>& poses_T_world_body;
  double voxel_m = 0.0;
};

GeorefRunReport georeferenceRun(const Trajectory& trajectory, const georef::GnssInput& gnss,
                                const SystemConfig& config, const std::string& recording_name,
                                const RunMap& map, const std::filesystem::path& out_dir);

/// A scan's pose in the grid as the online georeferencer gave it when the scan was processed.
struct OnlineGridPose {
  georef::GridPose pose;
  Eigen::Matrix<double, 6, 1> sigma;  ///< of the estimate then: east, north, up, roll, pitch, yaw
  std::size_t fixes = 0;              ///< fixes the estimate used
};

/// DIR/trajectory_online_epsgNNNN.csv: one row per scan from the first online estimate on.
void writeOnlineGeoreference(const std::filesystem::path& dir,
                             const std::vector<OnlineGridPose>& poses, int epsg);

}  // namespace taiga::pipeline
