#include "taiga/pipeline/local_map.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

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
      point_statistics_(point_spacing_m) {
  setNdtResolutions(ndt_resolutions_m);
}

void LocalMap::setNdtResolutions(const std::vector<double>& ndt_resolutions_m) {
  if (ndt_resolutions_m.empty()) throw std::invalid_argument("LocalMap: no NDT resolution");
  if (!keyframes_.empty()) throw std::logic_error("LocalMap: NDT resolutions set on a full map");
  finishPendingBuild();
  in_use_ = {};
  ndt_statistics_.clear();
  // Only the NDT target needs cells; GICP uses the points.
  if (target_ == Target::kNdt)
    for (double resolution_m : ndt_resolutions_m)
      ndt_statistics_.emplace_back(resolution_m, ndt_cells_.cellsAt(resolution_m).stem_cells);
}

LocalMap::~LocalMap() {
  if (pending_.valid()) pending_.wait();
}

void LocalMap::finishPendingBuild() {
  if (pending_.valid()) in_use_ = pending_.get();
}

// The NDT branch (its statistics, then its targets) and the points branch (the point statistics,
// then the means, the kd-tree and the GICP cloud) are independent: run side by side. Each
// statistic is updated and each structure built by one thread, in the same order as before, so
// the result is the same on any number of threads. Removal subtracts exactly what adding added:
// the same points through the same pose.
LocalMap::SearchStructures LocalMap::update(const std::vector<const Keyframe*>& added,
                                            const std::vector<const Keyframe*>& removed) {
  struct InOdom {
    std::vector<Eigen::Vector3d> points;
    registration::BeamNoise beams;  ///< the keyframe's lidar and the range noise
  };
  auto inOdom = [&](const Keyframe& keyframe) {
    InOdom out{keyframe.points_in_keyframe,
               {keyframe.T_odom_keyframe * p_keyframe_lidar_, ndt_cells_.range_sigma_m,
                ndt_cells_.range_sigma_per_m}};
    for (Eigen::Vector3d& p : out.points) p = keyframe.T_odom_keyframe * p;
    return out;
  };
  std::vector<InOdom> added_in_odom, removed_in_odom;
  for (const Keyframe* keyframe : added) added_in_odom.push_back(inOdom(*keyframe));
  for (const Keyframe* keyframe : removed) removed_in_odom.push_back(inOdom(*keyframe));
  // Only statistics with circle moments (the stem cells') keep the beams' noise shares.
  auto account = [&](registration::VoxelStatistics& statistics) {
    for (const InOdom& keyframe : added_in_odom) statistics.add(keyframe.points, keyframe.beams);
    for (const InOdom& keyframe : removed_in_odom)
      statistics.remove(keyframe.points, keyframe.beams);
  };

  SearchStructures built;
  built.ndt_targets.resize(ndt_statistics_.size());
  auto ndt_branch = [&] {
    tbb::parallel_for(std::size_t{0}, ndt_statistics_.size(), [&](std::size_t i) {
      registration::VoxelStatistics& statistics = ndt_statistics_[i];
      account(statistics);
      built.ndt_targets[i] = std::make_unique<registration::NdtTarget>(
          statistics, ndt_cells_.cellsAt(statistics.resolution_m()));
    });
  };
  auto points_branch = [&] {
    account(point_statistics_);
    const std::vector<Eigen::Vector3d> points = point_statistics_.means();
    built.kd_tree = std::make_unique<registration::KdTree>(points);
    if (target_ == Target::kGicp)
      built.gicp_cloud = std::make_unique<registration::GicpCloud>(points, gicp_config_);
  };
  tbb::parallel_invoke(ndt_branch, points_branch);
  return built;
}

void LocalMap::addKeyframe(std::uint64_t id, const lie::SE3& T_odom_keyframe,
                           std::vector<Eigen::Vector3d> points_in_keyframe) {
  finishPendingBuild();  // it reads the statistics and keyframes that change now
  keyframes_.push_back({id, T_odom_keyframe, std::move(points_in_keyframe)});
  std::vector<Keyframe> dropped;
  while (static_cast<int>(keyframes_.size()) > max_keyframes_) {
    dropped.push_back(std::move(keyframes_.front()));
    keyframes_.pop_front();
  }
  // The statistics are brought up to date in the background, before the build: on the main
  // thread they made the keyframe's scan twice as slow as any other (bench/BENCHMARK.md,
  // "Session 37"). Nothing else reads them until finishPendingBuild().
  pending_ = std::async(std::launch::async,
                        [this, &added = keyframes_.back(), dropped = std::move(dropped)] {
                          std::vector<const Keyframe*> removed;
                          for (const Keyframe& keyframe : dropped) removed.push_back(&keyframe);
                          return update({&added}, removed);
                        });
  registrations_since_keyframe_ = 0;
}

void LocalMap::repose(
    const std::function<lie::SE3(std::uint64_t id, const lie::SE3& T_odom_keyframe)>&
        T_odom_keyframe_at) {
  finishPendingBuild();
  for (registration::VoxelStatistics& statistics : ndt_statistics_) statistics.clear();
  point_statistics_.clear();
  std::vector<const Keyframe*> all;
  for (Keyframe& keyframe : keyframes_) {
    keyframe.T_odom_keyframe = T_odom_keyframe_at(keyframe.id, keyframe.T_odom_keyframe);
    all.push_back(&keyframe);
  }
  in_use_ = {};  // so that beginRegistration() waits for the structures in the new frame
  if (!keyframes_.empty())
    pending_ = std::async(std::launch::async, [this, all] { return update(all, {}); });
}

void LocalMap::beginRegistration() {
  if (!pending_.valid()) return;
  const bool have_previous = in_use_.kd_tree != nullptr;
  if (have_previous && registrations_since_keyframe_++ < kScansOnPreviousMap) return;
  finishPendingBuild();
}

void LocalMap::clear() {
  finishPendingBuild();
  for (registration::VoxelStatistics& statistics : ndt_statistics_) statistics.clear();
  point_statistics_.clear();
  keyframes_.clear();
  in_use_ = {};
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
  for (const auto& target : in_use_.ndt_targets) targets.push_back(target.get());
  if (targets.empty()) throw std::logic_error("LocalMap: no NDT target in use");
  return targets;
}
const registration::KdTree& LocalMap::kdTree() const { return inUse(in_use_.kd_tree, "kd-tree"); }
const std::vector<Eigen::Vector3d>* LocalMap::pointsInUse() const {
  return in_use_.kd_tree ? &in_use_.kd_tree->points() : nullptr;
}
const registration::Occupancy& LocalMap::occupancy(double voxel_m) const {
  if (!in_use_.occupancy || in_use_.occupancy_voxel_m != voxel_m) {
    in_use_.occupancy = std::make_unique<registration::Occupancy>(kdTree().points(), voxel_m);
    in_use_.occupancy_voxel_m = voxel_m;
  }
  return *in_use_.occupancy;
}

const registration::NdtTarget& LocalMap::coarseNdtTarget(double resolution_m) const {
  std::unique_ptr<registration::NdtTarget>& target = in_use_.coarse_ndt_target;
  if (!target || target->resolution_m() != resolution_m)
    target = std::make_unique<registration::NdtTarget>(registration::NdtTarget::fromPoints(
        kdTree().points(), resolution_m, ndt_cells_.cellsAt(resolution_m)));
  return *target;
}

const registration::GicpCloud& LocalMap::gicpCloud() const {
  return inUse(in_use_.gicp_cloud, "GICP cloud");
}

}  // namespace taiga::pipeline
