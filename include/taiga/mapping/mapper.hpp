#pragma once
// The mapping back end of thesis 3.1.2: keyframes from the odometry enter the pose graph, loop
// closures are searched at most once per loop_min_interval_s of recording time and kept when
// they verify (loop_closure.hpp) and agree with the graph (the chi^2 of the cost they add).
// MappingThread runs it beside the odometry; the odometry waits for it only to take a graph
// snapshot two keyframes late (waitForSnapshot, pipeline/odometry_correction.hpp). With
// gnss_fusion on, GNSS fixes enter the graph too (gnss_fusion.hpp).

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <variant>
#include <vector>

#include "taiga/core/georef_config.hpp"
#include "taiga/core/mapping_config.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/core/sensor_samples.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/mapping/gnss_fusion.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/loop_closure.hpp"
#include "taiga/mapping/pose_graph.hpp"
#include "taiga/mapping/relocalization.hpp"

namespace taiga::mapping {

/// One loop closure attempt and what became of it (loops.csv).
struct LoopRecord {
  double t_s = 0.0;
  LoopAttempt attempt;
  double chi2 = 0.0;  ///< cost the loop added, as chi^2 (0 when it did not get that far)
};

/// One attempt to re-attach a map segment (relocalization.hpp) and what became of it.
struct RelocalizationRecord {
  double t_s = 0.0;
  std::uint64_t segment = 0;
  RelocalizationAttempt attempt;
  double chi2 = 0.0;  ///< cost the link added, as chi^2 (0 when it did not get that far)
};

/// Checks a loop candidate: loop_closure.hpp's verifyLoop, or a stand-in that injects false loops
/// in tests.
using LoopVerifier = std::function<LoopAttempt(
    const PoseGraph& graph, const KeyframeStore& store, std::size_t current,
    const LoopCandidate& candidate, const MappingConfig& config, const OdometryConfig& odometry)>;

class Mapper {
 public:
  /// Reads the keyframes' registration clouds from `store` (which must outlive the mapper).
  /// `gnss`: the GNSS receiver's settings for config.gnss_fusion (the georef section).
  Mapper(const MappingConfig& config, const OdometryConfig& odometry, const KeyframeStore& store,
         LoopVerifier verify_loop = verifyLoop, const GeorefConfig& gnss = GeorefConfig{});

  /// Keyframe `id` of the store (ids in order, from 0) at its odometry pose, in the odometry's
  /// map segment `segment`. The graph's map frame starts as the odom frame at the first
  /// keyframe; the first keyframe's segment is attached to the map, a later one once it is
  /// relocalized in it (relocalization.hpp). Until then its keyframes try that instead of loops.
  void addKeyframe(std::size_t id, double t_s, const lie::SE3& T_odom_body,
                   std::uint64_t segment = 0);
  /// A GNSS fix (recording clock); used when MappingConfig::gnss_fusion is on, ignored
  /// otherwise. It waits for the first keyframe at or after its time (gnss_fusion.hpp).
  void addGnssFix(const GnssFix& fix);
  /// End of the input: levels the map by R_level_map (the odometry's final estimate of its
  /// frame's tilt, PoseGraph::rotateMap) and solves the graph once more when GNSS factors
  /// arrived since its last solve. Call once, after the last keyframe and fix.
  void finish(const lie::SO3& R_level_map = lie::SO3());
  /// What became of the GNSS fixes and the estimated T_enu_map (none with fusion off).
  std::optional<GnssFusionReport> gnssReport() const;

  const PoseGraph& graph() const { return graph_; }
  /// The graph's current keyframe poses at the keyframes' times.
  Trajectory keyframeTrajectory() const;
  const std::vector<LoopRecord>& loopAttempts() const { return attempts_; }
  std::size_t loopClosures() const { return graph_.loops().size(); }
  const std::vector<RelocalizationRecord>& relocalizationAttempts() const {
    return relocalizations_;
  }
  /// Whether the keyframe's segment is the first or re-attached.
  bool attached(std::size_t keyframe) const;
  /// Segments that were re-attached to the map, in order (accepted attempts: the first link of
  /// each, and up to kSegmentLinks - 1 more).
  std::vector<std::uint64_t> reattachedSegments() const;

 private:
  void tryLoopClosure(std::size_t current, double t_s);
  /// A verified loop that the graph disputes (chi2 above loop_max_chi2, within
  /// kLoopPairMaxGraphChi2Factor times it) is kept when an earlier such loop, within
  /// kLoopPairKeyframes, agrees with it (PoseGraph::loopPairChi2 within loop_max_chi2); both
  /// are then added. Returns whether it was.
  bool acceptWithAgreeingLoop(LoopRecord& record);
  void tryRelocalization(std::size_t current, double t_s);
  /// The keyframes' stems for relocalize(), cached in stem_marks_ (none when relocalization_stems
  /// is off).
  KeyframeStemMarks stemMarksOf();
  /// Whether a later segment still looks for links to the map rather than loops: until it is
  /// attached, and then for more links (one registration's heading error would swing the whole
  /// segment about it) within kSegmentLinkKeyframes of the first.
  bool linking(std::uint64_t segment, std::size_t current) const;

  MappingConfig config_;
  OdometryConfig odometry_;
  const KeyframeStore& store_;
  LoopVerifier verify_loop_;
  PoseGraph graph_;
  std::vector<double> keyframe_times_s_;
  std::optional<GnssFusion> gnss_;
  std::optional<double> last_attempt_s_;
  std::vector<LoopRecord> attempts_;
  std::vector<std::size_t> disputed_loops_;  ///< attempts_ verified but refused by the graph
  static constexpr std::size_t kLoopPairKeyframes = 30;
  static constexpr double kLoopPairMaxGraphChi2Factor = 4.0;
  static constexpr int kSegmentLinks = 3;
  static constexpr std::size_t kSegmentLinkKeyframes = 20;
  struct SegmentLinks {
    std::size_t first_keyframe = 0;
    int count = 0;
  };
  std::uint64_t first_segment_ = 0;
  std::map<std::uint64_t, SegmentLinks> links_;  ///< of the re-attached segments
  std::optional<double> last_relocalization_s_;
  std::vector<RelocalizationRecord> relocalizations_;
  /// Each keyframe's stems in its body frame, found when a relocalization first needs them.
  std::map<std::size_t, std::vector<StemMark>> stem_marks_;
};

/// The mapping graph's poses of the newest keyframes right after it handled one keyframe: what
/// the odometry rebuilds its local map from (MappingConfig::correct_odometry).
struct GraphSnapshot {
  std::size_t keyframe = 0;                ///< the keyframe just handled, the last of the poses
  std::vector<lie::SE3> poses_T_map_body;  ///< keyframes keyframe - size + 1 ... keyframe
};

struct MappingThreadOptions {
  /// > 0: after every keyframe, keep a GraphSnapshot of this many keyframes for
  /// waitForSnapshot().
  std::size_t snapshot_keyframes = 0;
  /// Called on the mapping thread after every keyframe, with the graph as it is then (e.g. to
  /// rewrite the store's poses.tum, so that `taiga export-map` can export a running run's map).
  std::function<void(const Mapper&)> after_keyframe;
  /// The GNSS receiver's settings for MappingConfig::gnss_fusion (the georef section).
  GeorefConfig gnss;
};

/// A Mapper on its own thread. Messages are handled in order, so the result does not depend on
/// timing: the same recording gives the same map.
class MappingThread {
 public:
  MappingThread(const MappingConfig& config, const OdometryConfig& odometry,
                const KeyframeStore& store, MappingThreadOptions options = {});
  ~MappingThread();
  MappingThread(const MappingThread&) = delete;
  MappingThread& operator=(const MappingThread&) = delete;

  void addKeyframe(std::size_t id, double t_s, const lie::SE3& T_odom_body,
                   std::uint64_t segment = 0);
  /// Fixes are handled in the order of the calls, interleaved with the keyframes, so the
  /// result depends on that order only, not on the thread's timing.
  void addGnssFix(const GnssFix& fix);
  /// Waits until the thread has handled keyframe `keyframe` and returns the graph's snapshot
  /// taken then (options.snapshot_keyframes > 0), dropping the older ones; nothing when the
  /// thread failed (finish() rethrows). The snapshot depends on the order of the calls only, not
  /// on the thread's timing.
  std::optional<GraphSnapshot> waitForSnapshot(std::size_t keyframe);
  /// Waits until every message is handled, stops the thread, finishes the mapper
  /// (Mapper::finish, with R_level_map on the first call) and hands it out. Rethrows what the
  /// thread threw.
  Mapper& finish(const lie::SO3& R_level_map = lie::SO3());

 private:
  struct KeyframeMessage {
    std::size_t id;
    double t_s;
    lie::SE3 T_odom_body;
    std::uint64_t segment;
  };
  using Message = std::variant<KeyframeMessage, GnssFix>;
  void push(Message message);
  void work();
  /// After keyframe `id`: options_.after_keyframe and the snapshot.
  void publish(std::size_t id);

  Mapper mapper_;
  MappingThreadOptions options_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Message> queue_;
  std::deque<GraphSnapshot> snapshots_;  ///< oldest first
  std::condition_variable snapshot_ready_;
  bool stopping_ = false;
  bool finished_ = false;
  std::exception_ptr error_;
  std::thread worker_;
};

}  // namespace taiga::mapping
