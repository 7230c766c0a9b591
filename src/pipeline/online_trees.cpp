#include "online_trees.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <ctime>
#include <limits>

#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/trees/inventory.hpp"
#include "taiga/trees/tree_files.hpp"

namespace taiga::pipeline {
namespace {

constexpr std::size_t kKeyframesPerUpdate = 20;
constexpr double kRegionKeyframes_m = 10.0;  ///< keyframes this close to a new one are loaded
constexpr double kSeen_m = 15.0;             ///< stems this close to a new keyframe are refitted
/// Points this close to a new keyframe are kept (within kCropThinning_m more): the stems within
/// kSeen_m and the ground around them. A stem beyond, only added where the list has none, is
/// found by a later update or the final inventory.
constexpr double kCrop_m = kSeen_m + 1.0;
constexpr double kCropThinning_m = 1.0;

double distanceXy(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return (a.head<2>() - b.head<2>()).norm();
}

// CPU time of the calling thread: at idle priority the wall time of an update includes the
// waits for the CPU, which cost the run nothing.
double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

bool overlap(const trees::Stem& a, const trees::Stem& b) {
  return distanceXy(a.position_m, b.position_m) < 0.5 * (a.dbh_m + b.dbh_m) + 0.1;
}

}  // namespace

OnlineTrees::OnlineTrees(const mapping::KeyframeStore& store, std::filesystem::path trees_csv,
                         std::function<void(const std::vector<trees::Stem>&)> on_list)
    : store_(store),
      trees_csv_(std::move(trees_csv)),
      on_list_(std::move(on_list)),
      worker_([this] { run(); }) {}

OnlineTrees::~OnlineTrees() { stopWorker(); }

void OnlineTrees::stopWorker() {
  {
    std::lock_guard lock(mutex_);
    pending_.clear();
    jobs_.clear();
    stopping_ = true;
  }
  stop_.request_stop();  // the update in flight skips its remaining clusters
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void OnlineTrees::onScan(const ScanOutcome& /*scan*/, const lie::SE3& T_map_odom) {
  T_map_odom_ = T_map_odom;
}

void OnlineTrees::onKeyframe(std::uint64_t id, const ScanOutcome& scan) {
  const Keyframe keyframe{id, T_map_odom_ * scan.T_odom_body};
  std::lock_guard lock(mutex_);
  keyframes_.push_back(keyframe);
  pending_.push_back(keyframe);
  if (pending_.size() >= kKeyframesPerUpdate) {
    jobs_.push_back(std::move(pending_));
    pending_.clear();
    wake_.notify_all();
  }
}

void OnlineTrees::run() {
  // The tree map takes only the CPU that the odometry, the mapping and other programs leave
  // idle: on a machine that keeps up with the sensor that is most of it, and in a replay faster
  // than real time the updates fall behind and are merged instead of slowing the run.
  pthread_setname_np(pthread_self(), "taiga-trees");  // as top and perf show it
  const sched_param idle{.sched_priority = 0};
  if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0)
    logger().debug("online tree map: the worker runs at normal priority (SCHED_IDLE refused)");
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
    if (jobs_.empty()) return;  // stopping, and every job done
    // Jobs that queued while the worker waited for the CPU become one update of their region.
    std::vector<Keyframe> fresh;
    for (const std::vector<Keyframe>& job : jobs_)
      fresh.insert(fresh.end(), job.begin(), job.end());
    jobs_.clear();
    lock.unlock();
    const double start_s = threadCpuSeconds();
    try {
      update(fresh);
    } catch (const std::exception& e) {  // a keyframe file unreadable: the tree map goes on
      logger().warn("online tree map: update skipped: {}", e.what());
    }
    const double seconds = threadCpuSeconds() - start_s;
    lock.lock();
    work_s_ += seconds;
    ++updates_;
  }
}

void OnlineTrees::update(const std::vector<Keyframe>& fresh) {
  std::vector<Keyframe> all;
  {
    std::lock_guard lock(mutex_);
    all = keyframes_;
  }
  auto nearestFresh = [&](const Eigen::Vector3d& p) {
    double best = std::numeric_limits<double>::infinity();
    for (const Keyframe& k : fresh)
      best = std::min(best, distanceXy(p, k.T_map_body.translation()));
    return best;
  };
  // The crop tests each point against the new keyframes thinned to one per kCropThinning_m
  // (merged jobs can hold hundreds), so it keeps everything within kCrop_m of them.
  std::vector<Eigen::Vector3d> crop_centres_m;
  for (const Keyframe& k : fresh) {
    const Eigen::Vector3d& p = k.T_map_body.translation();
    if (std::none_of(crop_centres_m.begin(), crop_centres_m.end(),
                     [&](const Eigen::Vector3d& c) { return distanceXy(p, c) < kCropThinning_m; }))
      crop_centres_m.push_back(p);
  }
  auto inCrop = [&](const Eigen::Vector3d& p) {
    return std::any_of(crop_centres_m.begin(), crop_centres_m.end(), [&](const Eigen::Vector3d& c) {
      return distanceXy(p, c) <= kCrop_m + kCropThinning_m;
    });
  };
  std::vector<Eigen::Vector3d> points_m, sensors_m;
  std::vector<std::uint32_t> sensor_of;
  for (const Keyframe& k : all) {
    if (nearestFresh(k.T_map_body.translation()) > kRegionKeyframes_m) continue;
    sensors_m.push_back(k.T_map_body.translation());
    for (const Eigen::Vector3d& p_body : store_.load(k.id).positions) {
      const Eigen::Vector3d p = k.T_map_body * p_body;
      if (!inCrop(p)) continue;
      points_m.push_back(p);
      sensor_of.push_back(static_cast<std::uint32_t>(sensors_m.size() - 1));
    }
  }
  if (points_m.empty()) return;
  trees::InventoryOptions options;
  options.stems.stop = stop_.get_token();
  const trees::Inventory inventory =
      trees::takeInventory(points_m, options, trees::Viewpoints{sensors_m, sensor_of});
  if (stop_.stop_requested()) return;  // a part of the region's stems; finish() redoes them all

  for (const trees::Stem& stem : inventory.stems) {
    const bool seen_here = nearestFresh(stem.position_m) <= kSeen_m;
    const bool known = std::any_of(stems_.begin(), stems_.end(),
                                   [&](const trees::Stem& s) { return overlap(s, stem); });
    if (known && !seen_here) continue;
    std::erase_if(stems_, [&](const trees::Stem& s) { return overlap(s, stem); });
    stems_.push_back(stem);
  }
  writeCsv(stems_);
}

void OnlineTrees::writeCsv(const std::vector<trees::Stem>& stems) const {
  std::vector<trees::Stem> sorted = stems;
  trees::sortByPosition(sorted);
  // Written beside and renamed over: a reader never sees half a file.
  const std::filesystem::path partial = trees_csv_.string() + ".partial";
  trees::writeTreesCsv(partial, sorted, Eigen::Vector3d::Zero(), std::nullopt);
  std::filesystem::rename(partial, trees_csv_);
  if (on_list_) on_list_(sorted);
}

std::size_t OnlineTrees::finish(const std::vector<lie::SE3>& final_T_map_body) {
  stopWorker();  // the final pass below covers what it had left
  // The final list: one inventory of the whole map on the graph's final poses, the same as
  // `taiga trees RUN` on map.las. The incremental list saw each stem only from the keyframes
  // around it at the time, on live poses (docs/trees.md, "Online").
  std::vector<Eigen::Vector3d> points_m, sensors_m;
  std::vector<std::uint32_t> sensor_of;
  for (std::uint64_t id = 0; id < final_T_map_body.size() && id < store_.size(); ++id) {
    sensors_m.push_back(final_T_map_body[id].translation());
    for (const Eigen::Vector3d& p_body : store_.load(id).positions) {
      points_m.push_back(final_T_map_body[id] * p_body);
      sensor_of.push_back(static_cast<std::uint32_t>(sensors_m.size() - 1));
    }
  }
  try {
    // The recording has ended and the worker has stopped: the fits may take every thread the run
    // allows (compute.threads).
    trees::InventoryOptions options;
    options.stems.parallel = true;
    const trees::Inventory inventory =
        trees::takeInventory(points_m, options, trees::Viewpoints{sensors_m, sensor_of});
    writeCsv(inventory.stems);
    return inventory.stems.size();
  } catch (const InputError& e) {  // no points, or a map too large for one terrain grid
    logger().warn("tree map: the final inventory failed ({}); trees.csv holds the live list",
                  e.what());
    writeCsv(stems_);
    return stems_.size();
  }
}

double OnlineTrees::workSeconds() const {
  std::lock_guard lock(mutex_);
  return work_s_;
}

std::size_t OnlineTrees::updates() const {
  std::lock_guard lock(mutex_);
  return updates_;
}

}  // namespace taiga::pipeline
