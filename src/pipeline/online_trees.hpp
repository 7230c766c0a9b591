#pragma once
// The tree map while `taiga run` goes (mapping.trees, docs/trees.md "Online"): every 10 keyframes
// a worker thread takes the stems of the map around the newest keyframes and merges them into the
// tree list, written to RUN/trees.csv (replaced atomically, so it can be read while the run goes).
//
// - Region: the keyframes within 10 m of the new ones, their full scans from the keyframe store
//   placed with the live poses (T_map_odom * T_odom_body as published), cropped to 20 m around
//   the new keyframes; trees::takeInventory on it.
// - Merge: a stem within 15 m of a new keyframe has been seen from there and replaces the stems
//   it overlaps (re-fitted with the new views); one farther out (the region's edge) is added only
//   where the list has no stem yet.
// - Each stem is anchored to its nearest keyframe (stored in that keyframe's body frame), so when
//   the mapping graph moves keyframes (loop closures) the stem moves with them: finish() writes
//   the list on the graph's final poses, the frame of map.las.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/pipeline/slam_system.hpp"
#include "taiga/trees/stem_detection.hpp"

namespace taiga::pipeline {

class OnlineTrees final : public SlamObserver {
 public:
  OnlineTrees(const mapping::KeyframeStore& store, std::filesystem::path trees_csv);
  ~OnlineTrees() override;
  OnlineTrees(const OnlineTrees&) = delete;
  OnlineTrees& operator=(const OnlineTrees&) = delete;

  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;
  void onKeyframe(std::uint64_t id, const ScanOutcome& scan) override;

  /// After SlamSystem::finish(): the last keyframes' update, the stems on the final keyframe
  /// poses (one per keyframe, in id order), trees.csv written. Returns how many stems.
  std::size_t finish(const std::vector<lie::SE3>& final_T_map_body);
  /// Worker time spent on updates, s (the cost reported in summary.json).
  double workSeconds() const;

 private:
  struct Keyframe {
    std::uint64_t id;
    lie::SE3 T_map_body;  ///< live pose when it was added
  };
  struct AnchoredStem {
    trees::Stem stem;            ///< in the map frame at the anchor's live pose
    std::uint64_t anchor = 0;    ///< keyframe id
    Eigen::Vector3d p_anchor;    ///< breast-height point in the anchor's body frame
    Eigen::Vector3d axis_anchor; ///< unit axis direction in the anchor's body frame
  };
  void run();
  void update(const std::vector<Keyframe>& fresh);
  void writeCsv(const std::vector<trees::Stem>& stems) const;

  const mapping::KeyframeStore& store_;
  std::filesystem::path trees_csv_;
  lie::SE3 T_map_odom_;
  std::vector<Keyframe> keyframes_;  ///< every keyframe, live poses (worker reads under mutex_)
  std::vector<Keyframe> pending_;    ///< not yet in an update
  std::vector<AnchoredStem> stems_;  ///< worker-owned until finish()
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::vector<Keyframe>> jobs_;
  bool stopping_ = false;
  bool busy_ = false;
  double work_s_ = 0.0;
  std::thread worker_;
};

}  // namespace taiga::pipeline
