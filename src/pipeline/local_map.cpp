#include "taiga/pipeline/local_map.hpp"

#include <tbb/parallel_for.h>

#include <stdexcept>

namespace taiga::pipeline {

LocalMap::LocalMap(std::vector<double> ndt_resolutions_m, double point_spacing_m, int max_keyframes,
                   Target target, const registration::GicpConfig& gicp,
                   const registration::NdtConfig& ndt, const Eigen::Vector3d& p_keyframe_lidar)
    : max_keyframes_(max_keyframes),
      target_(target),
      gicp_config_(gicp),
      ndt_cells_(ndt),
      p_keyframe_lidar_(p_keyframe_lidar),
      point_means_(point_spacing_m) {
  setNdtResolutions(ndt_resolutions_m);
}

void LocalMap::setNdtResolutions(const std::vector<double>& ndt_resolutions_m) {
  if (ndt_resolutions_m.empty()) throw std::invalid_argument("LocalMap: no NDT resolution");
  if (!keyframes_.empty()) throw std::logic_error("LocalMap: NDT resolutions set on a full map");
  finishPendingBuild();
  ndt_in_use_ = {};
  points_in_use_ = {};
  ndt_statistics_.clear();
  // Only the NDT target needs cells; GICP uses the points.
  if (target_ == Target::kNdt)
    for (double resolution_m : ndt_resolutions_m)
      ndt_statistics_.emplace_back(resolution_m, ndt_cells_.cellsAt(resolution_m).stem_cells);
}

LocalMap::~LocalMap() {
  if (pending_ndt_.valid()) pending_ndt_.wait();
  if (pending_points_.valid()) pending_points_.wait();
}

void LocalMap::finishPendingBuild() {
  if (pending_ndt_.valid()) ndt_in_use_ = pending_ndt_.get();
  if (pending_points_.valid()) points_in_use_ = pending_points_.get();
  points_due_ = false;
  dropped_.clear();
}

const LocalMap::PointStructures& LocalMap::pointStructures() const {
  if (points_due_) {
    if (pending_points_.valid()) points_in_use_ = pending_points_.get();
    points_due_ = false;
  }
  return points_in_use_;
}

// The NDT targets and the points' structures are built by two tasks side by side, each from its
// own statistics, so that the registration can start on the targets while the points' index is
// still being built. Each statistic is updated and each structure built by one thread, in the same
// order as before, so the result is the same on any number of threads. Removal subtracts exactly
// what adding added: the same points through the same pose.
void LocalMap::startBuild(const std::vector<const Keyframe*>& added,
                          const std::vector<const Keyframe*>& removed) {
  // The keyframes' points in the odom frame, once for both tasks, with the rotation matrix made
  // once: each task applying SE3::act to every point (14.8 ns a point, bench/lie_bench) spent
  // about 0.8 ms of a keyframe; here it adds about 0.4 ms to the keyframe's scan (map_ms median
  // 3.8 -> 4.1 ms; real-time factor and p99 unchanged, bench/odometry_speed.sh).
  struct InOdom {
    std::vector<Eigen::Vector3d> points;
    registration::BeamNoise beams;
    int sign;  ///< +1 added, -1 removed
  };
  auto in_odom = std::make_shared<std::vector<InOdom>>();
  auto put = [&](const Keyframe& keyframe, int sign) {
    const Eigen::Matrix3d R = keyframe.T_odom_keyframe.rotation().matrix();
    const Eigen::Vector3d t = keyframe.T_odom_keyframe.translation();
    InOdom out{{},
               {R * p_keyframe_lidar_ + t, ndt_cells_.range_sigma_m, ndt_cells_.range_sigma_per_m},
               sign};
    out.points.reserve(keyframe.points_in_keyframe.size());
    for (const Eigen::Vector3d& p : keyframe.points_in_keyframe)
      out.points.push_back(R * p + t);  // as SE3::act, bit for bit
    in_odom->push_back(std::move(out));
  };
  for (const Keyframe* keyframe : added) put(*keyframe, +1);
  for (const Keyframe* keyframe : removed) put(*keyframe, -1);
  pending_ndt_ = std::async(std::launch::async, [this, in_odom] {
    NdtStructures built;
    built.targets.resize(ndt_statistics_.size());
    tbb::parallel_for(std::size_t{0}, ndt_statistics_.size(), [&](std::size_t i) {
      registration::VoxelStatistics& statistics = ndt_statistics_[i];
      // Only statistics with circle moments (the stem cells') keep the beams' noise shares.
      for (const InOdom& keyframe : *in_odom) {
        if (keyframe.sign > 0) {
          statistics.add(keyframe.points, keyframe.beams);
        } else {
          statistics.remove(keyframe.points, keyframe.beams);
        }
      }
      built.targets[i] = std::make_unique<registration::NdtTarget>(
          statistics, ndt_cells_.cellsAt(statistics.resolution_m()));
    });
    return built;
  });
  pending_points_ = std::async(std::launch::async, [this, in_odom] {
    for (const InOdom& keyframe : *in_odom) {
      if (keyframe.sign > 0) {
        point_means_.add(keyframe.points);
      } else {
        point_means_.remove(keyframe.points);
      }
    }
    PointStructures built;
    // The index buckets the means by its cells: they need no sort, and come out of it in an
    // order local enough for the GICP cloud's kd-tree.
    built.nearest = std::make_unique<registration::VoxelNearest>(point_means_.meansInTableOrder(),
                                                                 kNearestCell_m);
    if (target_ == Target::kGicp) {
      built.gicp_cloud =
          std::make_unique<registration::GicpCloud>(built.nearest->points(), gicp_config_);
    }
    return built;
  });
}

void LocalMap::addKeyframe(std::uint64_t id, const lie::SE3& T_odom_keyframe,
                           std::vector<Eigen::Vector3d> points_in_keyframe) {
  finishPendingBuild();  // it reads the statistics and keyframes that change now
  keyframes_.push_back({id, T_odom_keyframe, std::move(points_in_keyframe)});
  while (static_cast<int>(keyframes_.size()) > max_keyframes_) {
    dropped_.push_back(std::move(keyframes_.front()));
    keyframes_.pop_front();
  }
  // The statistics are brought up to date in the background, before the build: on the main
  // thread they made the keyframe's scan twice as slow as any other (bench/BENCHMARK.md,
  // "Session 37"). Nothing else reads them until finishPendingBuild().
  std::vector<const Keyframe*> removed;
  for (const Keyframe& keyframe : dropped_) removed.push_back(&keyframe);
  startBuild({&keyframes_.back()}, removed);
  registrations_since_keyframe_ = 0;
}

void LocalMap::repose(
    const std::function<lie::SE3(std::uint64_t id, const lie::SE3& T_odom_keyframe)>&
        T_odom_keyframe_at) {
  finishPendingBuild();
  for (registration::VoxelStatistics& statistics : ndt_statistics_) statistics.clear();
  point_means_.clear();
  std::vector<const Keyframe*> all;
  for (Keyframe& keyframe : keyframes_) {
    keyframe.T_odom_keyframe = T_odom_keyframe_at(keyframe.id, keyframe.T_odom_keyframe);
    all.push_back(&keyframe);
  }
  // No structures in use: beginRegistration() waits for those in the new frame.
  ndt_in_use_ = {};
  points_in_use_ = {};
  if (!keyframes_.empty()) startBuild(all, {});
}

void LocalMap::beginRegistration() {
  if (!pending_ndt_.valid()) return;
  const bool have_previous = !ndt_in_use_.targets.empty() || points_in_use_.nearest != nullptr;
  if (have_previous && registrations_since_keyframe_++ < kScansOnPreviousMap) return;
  // The NDT targets now; the points' structures at their first use, after the registration
  // (the fitness), unless the registration searches them (GICP).
  ndt_in_use_ = pending_ndt_.get();
  points_due_ = true;
  if (target_ == Target::kGicp) pointStructures();
}

void LocalMap::clear() {
  finishPendingBuild();
  for (registration::VoxelStatistics& statistics : ndt_statistics_) statistics.clear();
  point_means_.clear();
  keyframes_.clear();
  ndt_in_use_ = {};
  points_in_use_ = {};
}

std::size_t LocalMap::numPoints() const {
  std::size_t n = 0;
  for (const Keyframe& keyframe : keyframes_) n += keyframe.points_in_keyframe.size();
  return n;
}

namespace {
template <typename T>
const T& inUse(const std::unique_ptr<T>& structure, const char* what) {
  if (!structure) throw std::logic_error(std::string("LocalMap: no ") + what + " in use");
  return *structure;
}
}  // namespace

std::vector<const registration::NdtTarget*> LocalMap::ndtTargets() const {
  std::vector<const registration::NdtTarget*> targets;
  for (const auto& target : ndt_in_use_.targets) targets.push_back(target.get());
  if (targets.empty()) throw std::logic_error("LocalMap: no NDT target in use");
  return targets;
}
const registration::VoxelNearest& LocalMap::nearest() const {
  return inUse(pointStructures().nearest, "nearest-point index");
}
const std::vector<Eigen::Vector3d>* LocalMap::pointsInUse() const {
  const PointStructures& in_use = pointStructures();
  return in_use.nearest ? &in_use.nearest->points() : nullptr;
}
const registration::Occupancy& LocalMap::occupancy(double voxel_m) const {
  const PointStructures& in_use = pointStructures();
  if (!in_use.occupancy || in_use.occupancy_voxel_m != voxel_m) {
    in_use.occupancy = std::make_unique<registration::Occupancy>(nearest().points(), voxel_m);
    in_use.occupancy_voxel_m = voxel_m;
  }
  return *in_use.occupancy;
}

const registration::NdtTarget& LocalMap::coarseNdtTarget(double resolution_m) const {
  std::unique_ptr<registration::NdtTarget>& target = pointStructures().coarse_ndt_target;
  if (!target || target->resolution_m() != resolution_m)
    target = std::make_unique<registration::NdtTarget>(registration::NdtTarget::fromPoints(
        nearest().points(), resolution_m, ndt_cells_.cellsAt(resolution_m)));
  return *target;
}

const registration::GicpCloud& LocalMap::gicpCloud() const {
  return inUse(pointStructures().gicp_cloud, "GICP cloud");
}

}  // namespace taiga::pipeline
