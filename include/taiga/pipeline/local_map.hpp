#pragma once
// The local map that scans are registered to: the points of the latest keyframes, each in its
// body frame with its pose in the odom frame, so that corrected poses can move them (repose()).
// Its NDT cells come from incremental voxel statistics, so adding a keyframe and dropping the
// oldest costs only their own points (registration/voxel_statistics.hpp).
//
// The search structures (NDT targets or GICP cloud, and the points' nearest-point index for the
// fitness score) are rebuilt after each keyframe by two background tasks, the NDT targets' (about
// 20 ms on one core for an OS0-128 map) and the points' (about 13 ms; bench/local_map_bench),
// while the next scan is registered against the previous structures.
// The hand-over is counted in scans, not in time: the structures with keyframe k are used from
// the second registration after it, waiting for the build if need be, so results do not depend
// on the machine's speed or load. The NDT targets are handed over before that registration, the
// points' structures at their first use (the fitness, after it), so their build has the
// registration's time to finish.

#include <Eigen/Core>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/registration/correlative_search.hpp"
#include "taiga/registration/gicp.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/voxel_nearest.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::pipeline {

class LocalMap {
 public:
  /// Which registration target the map serves.
  enum class Target { kNdt, kGicp };
  /// Registrations after a keyframe that still use the structures without it. The background
  /// update and build take about two scans' time on two cores, so the second scan after a
  /// keyframe often waits for them; 2 removed that wait but lost a lidar-only walk's
  /// relocalization after a blind stretch (bench/BENCHMARK.md, "Session 37").
  static constexpr int kScansOnPreviousMap = 1;
  /// The cells of the points' nearest-point index: the fitness searches 2 m, and 1 m cells built
  /// and searched fastest (bench/local_map_bench; 0.3-1.3 m tried).
  static constexpr double kNearestCell_m = 1.0;

  /// NDT cells at each of ndt_resolutions_m (coarse to fine, at least one); the points (fitness,
  /// GICP) one per point_spacing_m voxel, so overlapping keyframes do not multiply their number.
  /// `ndt`: the cell rules of the NDT targets (NdtTarget; not its resolutions); with its range
  /// noise set, the stem cells take it out along each point's beam from the lidar at
  /// `p_keyframe_lidar` (the lidar's position in a keyframe's frame).
  LocalMap(std::vector<double> ndt_resolutions_m, double point_spacing_m, int max_keyframes,
           Target target, const registration::GicpConfig& gicp = {},
           const registration::NdtConfig& ndt = {},
           const Eigen::Vector3d& p_keyframe_lidar = Eigen::Vector3d::Zero());
  ~LocalMap();
  LocalMap(const LocalMap&) = delete;  // the background build refers to this object
  LocalMap& operator=(const LocalMap&) = delete;

  /// Adds one keyframe (its time, pose and points in its body frame), drops the oldest keyframe
  /// beyond max_keyframes, and starts building the search structures in the background.
  void addKeyframe(std::uint64_t id, const lie::SE3& T_odom_keyframe,
                   std::vector<Eigen::Vector3d> points_in_keyframe);
  /// Moves every keyframe to a new pose (`T_odom_keyframe_at(id, old T_odom_keyframe)`), e.g.
  /// the mapping graph's after a loop closure, and rebuilds the search structures from them. The
  /// next registration waits for them: the old ones hold the old poses.
  void repose(const std::function<lie::SE3(std::uint64_t id, const lie::SE3& T_odom_keyframe)>&
                  T_odom_keyframe_at);
  /// Drops every keyframe.
  void clear();
  /// Call once before each registration: hands the background build over when its turn has come
  /// (at once when there was no map before).
  void beginRegistration();

  bool empty() const { return keyframes_.empty(); }
  std::size_t numKeyframes() const { return keyframes_.size(); }
  std::size_t numPoints() const;

  /// The structures in use (logic_error for the other target's); the NDT targets coarse to fine.
  std::vector<const registration::NdtTarget*> ndtTargets() const;
  /// The local map's points (one per point_spacing_m voxel) for nearest-point queries (the
  /// fitness, the wide basin's overlap).
  const registration::VoxelNearest& nearest() const;
  /// The points the registration searches now (one per point_spacing_m voxel, odom frame), or
  /// nullptr before the first build: what a viewer shows as the local map.
  const std::vector<Eigen::Vector3d>* pointsInUse() const;
  const registration::GicpCloud& gicpCloud() const;
  /// The voxels (of edge voxel_m) that the points occupy, for the correlative search;
  /// built at the first call on the structures in use (none is built for maps never searched).
  const registration::Occupancy& occupancy(double voxel_m) const;
  /// NDT cells of edge resolution_m over the points, for a first pass from a guess that
  /// may be decimetres and degrees off (across a gap in the IMU readings) on a map whose own
  /// cells are only fine; built at the first call on the structures in use, like occupancy().
  const registration::NdtTarget& coarseNdtTarget(double resolution_m) const;

 private:
  /// Sets the NDT passes (coarse to fine, at least one); only while the map is empty.
  void setNdtResolutions(const std::vector<double>& ndt_resolutions_m);
  struct NdtStructures {
    std::vector<std::unique_ptr<registration::NdtTarget>> targets;  ///< coarse to fine
  };
  struct PointStructures {
    std::unique_ptr<registration::VoxelNearest> nearest;
    std::unique_ptr<registration::GicpCloud> gicp_cloud;
    mutable std::unique_ptr<registration::Occupancy> occupancy;  ///< built on demand
    mutable double occupancy_voxel_m = 0.0;
    mutable std::unique_ptr<registration::NdtTarget> coarse_ndt_target;  ///< built on demand
  };
  /// Waits for the background builds and makes them the ones in use.
  void finishPendingBuild();
  /// The points' structures in use, handed over first when beginRegistration() made them due.
  const PointStructures& pointStructures() const;

  int max_keyframes_;
  Target target_;
  registration::GicpConfig gicp_config_;
  registration::NdtConfig ndt_cells_;  ///< the NDT targets' cell rules
  Eigen::Vector3d p_keyframe_lidar_;
  struct Keyframe {
    std::uint64_t id = 0;
    lie::SE3 T_odom_keyframe;
    std::vector<Eigen::Vector3d> points_in_keyframe;
  };
  /// Starts bringing the statistics up to date (adding keyframes' points in the odom frame,
  /// removing others') and building the search structures from them, in the background.
  void startBuild(const std::vector<const Keyframe*>& added,
                  const std::vector<const Keyframe*>& removed);

  std::deque<Keyframe> keyframes_;
  std::vector<registration::VoxelStatistics> ndt_statistics_;  ///< NDT cells, coarse to fine
  registration::VoxelMeans point_means_;  ///< one mean per point_spacing_m voxel
  std::vector<Keyframe> dropped_;  ///< removed from the statistics by the pending build
  NdtStructures ndt_in_use_;
  mutable PointStructures points_in_use_;
  // The pending builds read the statistics and keyframes: those wait for them.
  std::future<NdtStructures> pending_ndt_;
  mutable std::future<PointStructures> pending_points_;
  mutable bool points_due_ = false;  ///< hand pending_points_ over at the next use
  int registrations_since_keyframe_ = 0;
};

}  // namespace taiga::pipeline
