#pragma once
// Keyframes on disk, so that memory stays flat however long the recording (issue 7, item 4).
//
// add() writes the keyframe's full-resolution deskewed scan (body frame) to
// DIR/NNNNNN.tkf (keyframe_file.hpp) at once and keeps in RAM only what the mapping needs
// often: time, pose and point count. When registration_voxel_m > 0, registrationCloud() gives a
// voxel-filtered, positions-only copy of the scan for loop closure; only the
// registration_cache_keyframes most recently used copies stay in RAM (least recently used
// evicted), and a copy not cached is rebuilt from the keyframe file with the same deterministic
// filter, so it is bit for bit the copy add() made. load() reads the full scan back. The poses
// are kept in RAM; setPoses() replaces them when the mapping
// graph corrects them, and writePoses() saves them as DIR/poses.tum (TUM, T_map_body, one line
// per keyframe in id order), so that `taiga export-map DIR` re-exports a finished run with its
// final poses, or a running one with its current poses.
//
// Ids are 0, 1, 2, ... in the order of add(). Thread-safe: one thread may add() while others
// call load(), registrationCloud(), pose() or setPoses(). A registration copy handed out stays
// valid after the cache evicts it (shared ownership).

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <vector>

#include "taiga/core/point_cloud.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/lie/se3.hpp"
#include "taiga/preprocess/voxel_filter.hpp"

namespace taiga::mapping {

struct KeyframeStoreOptions {
  /// > 0: registrationCloud() gives a copy of each scan filtered to this voxel size, m. The
  /// odometry registers at 0.4 m (thesis 3.1.1). 0: no copies, registrationCloud() is empty.
  double registration_voxel_m = 0.0;
  /// The point standing for each voxel of the copies (OdometryConfig::voxel_point).
  preprocess::VoxelRepresentative registration_voxel_point =
      preprocess::VoxelRepresentative::centroid;
  /// How many registration copies stay in RAM (least recently used evicted; the others are
  /// rebuilt from disk when asked for). A loop attempt uses the current keyframe's copy and
  /// 2 x loop_submap_keyframes + 1 around the candidate (21 by default): 64 keeps those and the
  /// newest keyframes, ~15 MB at 0.4 m. 0: nothing cached, every call reads the file.
  std::size_t registration_cache_keyframes = 64;
};

/// What the registration-copy cache holds and has done (tests, benchmarks).
struct RegistrationCacheStatistics {
  std::size_t cached_keyframes = 0;  ///< copies in RAM now, <= registration_cache_keyframes
  std::uint64_t hits = 0;            ///< registrationCloud() calls served from RAM
  std::uint64_t rebuilt = 0;         ///< copies rebuilt from a keyframe file
};

/// What stays in RAM per keyframe.
struct KeyframeInfo {
  std::uint64_t id = 0;
  double t_s = 0.0;
  /// The odometry's T_odom_body from add() until setPoses() gives the graph's T_map_body.
  lie::SE3 T_map_body;
  std::uint64_t point_count = 0;
};

class KeyframeStore {
 public:
  /// A new store in `dir` (created; keyframe files and poses.tum already there are replaced).
  static KeyframeStore create(const std::filesystem::path& dir, KeyframeStoreOptions options = {});
  /// An existing store: poses.tum and the header of every keyframe file it implies (the full
  /// scans are read only when asked for, by load() or registrationCloud()). InputError naming
  /// the file when a file is missing, has the wrong size or disagrees with poses.tum.
  static KeyframeStore open(const std::filesystem::path& dir, KeyframeStoreOptions options = {});

  KeyframeStore(KeyframeStore&&) noexcept;
  KeyframeStore& operator=(KeyframeStore&&) noexcept;
  ~KeyframeStore();

  /// Stores a keyframe (its time, odometry pose and full scan in the body frame) and returns its
  /// id. t_s must be later than the previous keyframe's. InputError when the file cannot be
  /// written. `registration_positions`, when given, are the scan's points filtered as
  /// registrationCloud() filters them (the odometry's source cloud is): kept as its copy instead
  /// of filtering the scan again (5 ms of a keyframe on the odometry's thread).
  std::uint64_t add(double t_s, const lie::SE3& T_odom_body, const PointCloud& cloud_in_body,
                    const std::vector<Eigen::Vector3d>* registration_positions = nullptr);

  std::size_t size() const;
  bool empty() const { return size() == 0; }
  const std::filesystem::path& directory() const;
  /// The file of keyframe `id`: DIR/NNNNNN.tkf (six digits, more when needed).
  std::filesystem::path keyframePath(std::uint64_t id) const;

  /// The full scan of keyframe `id` in the body frame, read from disk (bit for bit as added).
  PointCloud load(std::uint64_t id) const;
  /// The voxel-filtered scan in the body frame, positions only (no other channel); empty when
  /// registration_voxel_m is 0. From the cache, or rebuilt from the keyframe file (InputError as
  /// for load()) and cached.
  std::shared_ptr<const PointCloud> registrationCloud(std::uint64_t id) const;
  RegistrationCacheStatistics registrationCacheStatistics() const;

  KeyframeInfo info(std::uint64_t id) const;
  lie::SE3 pose(std::uint64_t id) const;
  /// Every keyframe's T_map_body, in id order.
  std::vector<lie::SE3> poses() const;
  /// The poses as a trajectory (keyframe times).
  Trajectory trajectory() const;
  /// Replaces every pose (one per keyframe, in id order) in RAM; writePoses() saves them.
  void setPoses(const std::vector<lie::SE3>& poses_T_map_body);
  /// Rewrites DIR/poses.tum from the poses in RAM (write to a temporary file, then rename).
  void writePoses() const;
  /// Rewrites DIR/poses.tum with these poses of keyframes 0, 1, ... (their times and T_map_body;
  /// may be fewer than the store holds), the same way. A running `taiga run` publishes its
  /// mapping graph's current poses so, and open() then sees a consistent snapshot of the run:
  /// every keyframe it lists has its file complete.
  void writePoses(const Trajectory& poses_T_map_body) const;

 private:
  struct Impl;
  explicit KeyframeStore(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace taiga::mapping
