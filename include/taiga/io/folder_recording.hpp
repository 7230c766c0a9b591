#pragma once
// Folder recordings, for users without ROS (layout in docs/recordings.md):
//
//   RECORDING/scans/<start time>.pcd|.ply   one file per scan; the name is the scan's start time in
//                                           s (1700000000.100000.pcd) or ns (1700000000100000000.pcd)
//   RECORDING/imu.csv                       t_s,ax,ay,az,wx,wy,wz[,qx,qy,qz,qw]
//   RECORDING/gnss.csv                      optional: t_s,lat_deg,lon_deg,height_m
//                                           [,var_e_m2,var_n_m2,var_u_m2][,status]
//
// CSV columns are found by their header names, in any order; lines starting with '#' are comments.

#include <filesystem>
#include <memory>
#include <vector>

#include "taiga/io/recording.hpp"

namespace taiga::io {

struct FolderScanFile {
  std::filesystem::path path;
  double stamp_s = 0.0;  ///< from the file name
};

/// True when `dir` looks like a folder recording (has scans/ or imu.csv).
bool isFolderRecording(const std::filesystem::path& dir);

/// The scan files of a folder recording, in time order. Throws InputError naming a file whose
/// name is not a time, or two files with the same time.
std::vector<FolderScanFile> listFolderScans(const std::filesystem::path& dir);

/// The scan stream, the IMU stream (if imu.csv exists) and the GNSS stream (if gnss.csv exists).
std::vector<std::unique_ptr<StreamSource>> openFolderStreams(const std::filesystem::path& dir,
                                                             const RecordingConfig& recording, const RigConfig& rig);

}  // namespace taiga::io
