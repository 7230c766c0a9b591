#pragma once
// Keyframes on disk, so that memory stays flat however long the recording (issue 7, item 4).
//
// add() writes the keyframe's full-resolution deskewed scan (body frame) to
// DIR/NNNNNN.tkf (keyframe_file.hpp) at once and keeps in RAM only what the mapping needs
// often: time, pose, point count and, when
// registration_voxel_m > 0, a voxel-filtered copy of the scan for loop closure
// (registrationCloud()). load() reads the full scan back. The poses are kept in RAM; setPoses()
// replaces them when the world frame is levelled or the mapping graph corrects them, and
// writePoses() saves them as DIR/poses.tum (TUM, T_world_body, one line per keyframe in id
// order), so that `taiga export-map DIR` re-exports a finished run with its final poses.
//
// Ids are 0, 1, 2, ... in the order of add(). Thread-safe: one thread may add() while others
// call load(), registrationCloud(), pose() or setPoses().

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <vector>

#include "taiga/core/point_cloud.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::mapping {

struct KeyframeStoreOptions {
  /// > 0: keep a copy of each scan filtered to this voxel size in RAM (registrationCloud()), m.
  /// The odometry registers at 0.4 m (thesis 3.1.1). 0: keep nothing but the metadata.
  double registration_voxel_m = 0.0;
};

/// What stays in RAM per keyframe.
struct KeyframeInfo {
  std::uint64_t id = 0;
  double t_s = 0.0;
  lie::SE3 T_world_body;
  std::uint64_t point_count = 0;
};

class KeyframeStore {
 public:
  /// A new store in `dir` (created; keyframe files and poses.tum already there are replaced).
  static KeyframeStore create(const std::filesystem::path& dir, KeyframeStoreOptions options = {});
  /// An existing store: poses.tum and the header of every keyframe file it implies (the full
  /// scans are read only when registration_voxel_m > 0). InputError naming the file when a file
  /// is missing, corrupt or disagrees with poses.tum.
  static KeyframeStore open(const std::filesystem::path& dir, KeyframeStoreOptions options = {});

  KeyframeStore(KeyframeStore&&) noexcept;
  KeyframeStore& operator=(KeyframeStore&&) noexcept;
  ~KeyframeStore();

  /// Stores a keyframe (its time, pose and full scan in the body frame) and returns its id.
  /// t_s must be later than the previous keyframe's. InputError when the file cannot be written.
  std::uint64_t add(double t_s, const lie::SE3& T_world_body, const PointCloud& cloud_in_body);

  std::size_t size() const;
  bool empty() const { return size() == 0; }
  const std::filesystem::path& directory() const;
  /// The file of keyframe `id`: DIR/NNNNNN.tkf (six digits, more when needed).
  std::filesystem::path keyframePath(std::uint64_t id) const;

  /// The full scan of keyframe `id` in the body frame, read from disk (bit for bit as added).
  PointCloud load(std::uint64_t id) const;
  /// The voxel-filtered scan in the body frame; empty when registration_voxel_m is 0.
  std::shared_ptr<const PointCloud> registrationCloud(std::uint64_t id) const;

  KeyframeInfo info(std::uint64_t id) const;
  lie::SE3 pose(std::uint64_t id) const;
  /// Every keyframe's T_world_body, in id order.
  std::vector<lie::SE3> poses() const;
  /// The poses as a trajectory (keyframe times).
  Trajectory trajectory() const;
  /// Replaces every pose (one per keyframe, in id order) in RAM; writePoses() saves them.
  void setPoses(const std::vector<lie::SE3>& poses_T_world_body);
  /// Rewrites DIR/poses.tum from the poses in RAM (write to a temporary file, then rename).
  void writePoses() const;

 private:
  struct Impl;
  explicit KeyframeStore(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace taiga::mapping
