#pragma once
// The tree map while `taiga run` goes (mapping.trees, docs/trees.md "Online"): every 20 keyframes
// a worker thread takes the stems of the map around the newest keyframes and merges them into the
// tree list, written to RUN/trees.csv (replaced atomically, so it can be read while the run goes).
//
// - Region: the keyframes within 10 m of the new ones, their full scans from the keyframe store
//   placed with the live poses (T_map_odom * T_odom_body as published), cropped to 16-17 m of
//   the new keyframes; trees::takeInventory on it.
// - Priority: the worker runs at idle priority (SCHED_IDLE); jobs that queue meanwhile are merged.
// - Merge: a stem within 15 m of a new keyframe has been seen from there and replaces the stems
//   it overlaps (re-fitted with the new views); one farther out (the region's edge) is added only
//   where the list has no stem yet.
// - finish(): the final list is one inventory of the whole map on the graph's final poses (what
//   `taiga trees RUN` gives from map.las): the incremental list saw each stem only from the
//   keyframes around it at the time.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <mutex>
#include <stop_token>
#include <thread>
#include <vector>

#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/pipeline/slam_system.hpp"
#include "taiga/trees/stem_detection.hpp"

namespace taiga::pipeline {

class OnlineTrees final : public SlamObserver {
 public:
  /// `on_list` (optional) gets each list as it is written (on the worker thread, and the final
  /// one on the caller's), e.g. for the live stream.
  OnlineTrees(const mapping::KeyframeStore& store, std::filesystem::path trees_csv,
              std::function<void(const std::vector<trees::Stem>&)> on_list = {});
  ~OnlineTrees() override;
  OnlineTrees(const OnlineTrees&) = delete;
  OnlineTrees& operator=(const OnlineTrees&) = delete;

  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;
  void onKeyframe(std::uint64_t id, const ScanOutcome& scan) override;

  /// After SlamSystem::finish(): the inventory of the whole map on the final keyframe poses (one
  /// per keyframe, in id order), written to trees.csv. Returns how many stems.
  std::size_t finish(const std::vector<lie::SE3>& final_T_map_body);
  /// The worker's CPU time on updates, s (the cost reported in summary.json).
  double workSeconds() const;
  /// Updates of the live list during the run (jobs that queued while the worker waited for the
  /// CPU are merged into one).
  std::size_t updates() const;

 private:
  struct Keyframe {
    std::uint64_t id;
    lie::SE3 T_map_body;  ///< live pose when it was added
  };
  void run();
  /// Ends the worker: queued updates dropped, the one in flight cut short (after a stop an update
  /// writes nothing), the thread joined.
  void stopWorker();
  void update(const std::vector<Keyframe>& fresh);
  void writeCsv(const std::vector<trees::Stem>& stems) const;

  const mapping::KeyframeStore& store_;
  std::filesystem::path trees_csv_;
  std::function<void(const std::vector<trees::Stem>&)> on_list_;
  lie::SE3 T_map_odom_;
  std::vector<Keyframe> keyframes_;  ///< every keyframe, live poses (worker reads under mutex_)
  std::vector<Keyframe> pending_;    ///< not yet in an update
  std::vector<trees::Stem> stems_;   ///< the incremental list, worker-owned
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::vector<Keyframe>> jobs_;
  bool stopping_ = false;
  std::stop_source stop_;  ///< finish() cuts the update in flight short: the final pass covers it
  double work_s_ = 0.0;
  std::size_t updates_ = 0;
  std::thread worker_;
};

}  // namespace taiga::pipeline
