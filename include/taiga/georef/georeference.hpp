#pragma once
// The whole post-fit georeferencing of a finished trajectory, shared by `taiga georef` and the end
// of `taiga run`: gate the fixes and put them in a local ENU frame, associate them with the
// trajectory by time, fit T_enu_world with the chosen method, and express every pose in the
// projected CRS. Errors are InputErrors that name the inputs by the names given.

#include <filesystem>
#include <string>
#include <vector>

#include "taiga/core/georef_config.hpp"
#include "taiga/core/rig_config.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/georef/association.hpp"
#include "taiga/georef/fit.hpp"
#include "taiga/georef/fix_preparation.hpp"
#include "taiga/georef/georef_files.hpp"
#include "taiga/georef/grid_output.hpp"

namespace taiga::georef {

struct GeorefSettings {
  GeorefMethod method = GeorefMethod::kRobust;
  int epsg = 3067;  ///< ETRS-TM35FIN
  FixGating gating;
  AssociationOptions association;
  FitOptions fit;
};

/// The settings of a config's georef section (InputError for an unknown method).
GeorefSettings settingsFrom(const GeorefConfig& config);

struct Georeference {
  GeorefReport report;          ///< what georef.yaml holds, the fit included
  std::vector<GridPose> poses;  ///< every pose of the trajectory in the projected CRS
  std::vector<AssociatedFix> fixes;  ///< the fixes fitted (report.fit.inlier tells the used ones)
};

/// `trajectory_name` and `gnss_name` only name the inputs in messages and in the report. pf6
/// takes the IMU's absolute orientations from `input` and the IMU's mounting from `rig`.
Georeference georeference(const Trajectory& trajectory, const GnssInput& input,
                          const GeorefSettings& settings, const RigConfig& rig,
                          const std::string& trajectory_name, const std::string& gnss_name);

/// Writes DIR/trajectory_epsgNNNN.csv, DIR/trajectory.geojson, DIR/georef.yaml and DIR/fixes.csv.
void writeGeoreference(const std::filesystem::path& dir, const Georeference& georeference,
                       const std::string& trajectory_name);

}  // namespace taiga::georef
