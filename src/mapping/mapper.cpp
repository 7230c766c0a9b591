#include "taiga/mapping/mapper.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "taiga/core/log.hpp"

namespace taiga::mapping {

Mapper::Mapper(const MappingConfig& config, const OdometryConfig& odometry,
               const KeyframeStore& store, LoopVerifier verify_loop, const GeorefConfig& gnss)
    : config_(config),
      odometry_(odometry),
      store_(store),
      verify_loop_(std::move(verify_loop)),
      graph_(config) {
  if (config.gnss_fusion) gnss_.emplace(config, gnss);
}

void Mapper::addKeyframe(std::size_t id, double t_s, const lie::SE3& T_odom_body,
                         std::uint64_t segment) {
  const std::size_t index = graph_.addKeyframe(T_odom_body, segment);
  if (index != id) throw std::logic_error("Mapper: keyframes must arrive in id order");
  keyframe_times_s_.push_back(t_s);
  if (index == 0) first_segment_ = segment;
  if (gnss_ && gnss_->afterKeyframe(graph_, keyframe_times_s_)) graph_.optimize();
  if (segment != first_segment_ && linking(segment, index)) {
    if (config_.relocalization) tryRelocalization(index, t_s);
    return;
  }
  if (!config_.loop_closure) return;
  if (last_attempt_s_ && t_s - *last_attempt_s_ < config_.loop_min_interval_s) return;
  tryLoopClosure(index, t_s);
}

void Mapper::addGnssFix(const GnssFix& fix) {
  if (gnss_) gnss_->addFix(fix);
}

void Mapper::finish(const lie::SO3& R_level_map) {
  graph_.rotateMap(R_level_map);
  if (gnss_ && gnss_->finish(graph_)) graph_.optimize();
}

Trajectory Mapper::keyframeTrajectory() const {
  Trajectory out;
  for (std::size_t k = 0; k < graph_.size(); ++k) out.append(keyframe_times_s_[k], graph_.pose(k));
  return out;
}

std::optional<GnssFusionReport> Mapper::gnssReport() const {
  if (!gnss_) return std::nullopt;
  return gnss_->report(graph_);
}

std::vector<std::uint64_t> Mapper::reattachedSegments() const {
  std::vector<std::uint64_t> out;
  for (const auto& [segment, links] : links_) out.push_back(segment);
  return out;
}

bool Mapper::attached(std::size_t keyframe) const {
  const std::uint64_t segment = graph_.segment(keyframe);
  return segment == first_segment_ || links_.contains(segment);
}

bool Mapper::linking(std::uint64_t segment, std::size_t current) const {
  const auto links = links_.find(segment);
  if (links == links_.end()) return true;  // not attached yet
  return links->second.count < kSegmentLinks &&
         current - links->second.first_keyframe < kSegmentLinkKeyframes;
}

KeyframeStemMarks Mapper::stemMarksOf() {
  if (!config_.relocalization_stems) return {};
  return [this](std::size_t k) -> const std::vector<StemMark>& {
    auto [it, fresh] = stem_marks_.try_emplace(k);
    if (fresh) it->second = scanStemMarks(store_.load(k), graph_.pose(k).rotation());
    return it->second;
  };
}

void Mapper::tryRelocalization(std::size_t current, double t_s) {
  if (last_relocalization_s_ && t_s - *last_relocalization_s_ < config_.loop_min_interval_s) return;
  const std::uint64_t segment = graph_.segment(current);
  // The map the segment is searched in: attached keyframes of the other segments.
  const Attached on_map = [this, segment](std::size_t k) {
    return graph_.segment(k) != segment && attached(k);
  };
  const std::optional<std::size_t> candidate =
      findRelocalizationCandidate(graph_, current, on_map, config_);
  if (!candidate) return;
  if (graph_.hasUnsolvedFactors()) graph_.optimize();
  last_relocalization_s_ = t_s;
  RelocalizationRecord record{
      .t_s = t_s,
      .segment = graph_.segment(current),
      .attempt = relocalize(graph_, store_, current, *candidate, on_map, config_, odometry_,
                            stemMarksOf())};
  if (record.attempt.accepted) {
    record.chi2 = graph_.addLoopIfConsistent(record.attempt.link, config_.loop_max_chi2);
    if (record.chi2 <= config_.loop_max_chi2) {
      const auto [links, first] =
          links_.try_emplace(segment, SegmentLinks{.first_keyframe = current});
      ++links->second.count;
      logger().info(
          "map segment {} {} at keyframe {} to keyframe {}: moved {:.2f} m / {:.2f} deg from "
          "{}, {:.0f} % of its points above the ground on the map ({:.0f} ms)",
          record.segment, first ? "re-attached" : "tied again", current, *candidate,
          record.attempt.correction_m, record.attempt.correction_deg,
          first ? "dead reckoning" : "the graph", 100.0 * record.attempt.overlap,
          record.attempt.search_ms);
    } else {
      record.attempt.accepted = false;
      record.attempt.note = fmt::format("inconsistent with the graph: chi2 {:.1f} above {:.1f}",
                                        record.chi2, config_.loop_max_chi2);
    }
  }
  if (!record.attempt.accepted)
    logger().debug("map segment {} not re-attached at keyframe {} ({:.0f} ms): {}", record.segment,
                   current, record.attempt.search_ms, record.attempt.note);
  relocalizations_.push_back(std::move(record));
}

void Mapper::tryLoopClosure(std::size_t current, double t_s) {
  const std::optional<LoopCandidate> candidate = findLoopCandidate(graph_, current, config_);
  // A segment never re-attached lies where dead reckoning put it, held by no factor: a loop to it
  // would pass any consistency test. Only a relocalization attaches it.
  if (!candidate || !attached(candidate->keyframe)) return;
  // The consistency test compares optimal costs: GNSS factors paced out of the last solve
  // would be charged to the loop.
  if (graph_.hasUnsolvedFactors()) graph_.optimize();
  last_attempt_s_ = t_s;
  LoopRecord record{
      .t_s = t_s, .attempt = verify_loop_(graph_, store_, current, *candidate, config_, odometry_)};
  if (record.attempt.accepted) {
    record.chi2 = graph_.addLoopIfConsistent(record.attempt.loop, config_.loop_max_chi2);
    if (record.chi2 <= config_.loop_max_chi2) {
      logger().debug("loop closed: keyframe {} to {}, {:.2f} m / {:.2f} deg, chi2 {:.1f}", current,
                     candidate->keyframe, record.attempt.correction_m,
                     record.attempt.correction_deg, record.chi2);
    } else if (!acceptWithAgreeingLoop(record)) {
      record.attempt.accepted = false;
      record.attempt.note = fmt::format("inconsistent with the graph: chi2 {:.1f} above {:.1f}",
                                        record.chi2, config_.loop_max_chi2);
      if (record.chi2 <= kLoopPairMaxGraphChi2Factor * config_.loop_max_chi2)
        disputed_loops_.push_back(attempts_.size());
    }
  }
  attempts_.push_back(std::move(record));
}

bool Mapper::acceptWithAgreeingLoop(LoopRecord& record) {
  // The graph's odometry sigmas are a random walk; a rig whose drift is systematic (a gyro
  // worse than its datasheet, an extrinsic error) drifts more than they allow, and its true
  // loops fail the test against the graph (harsh `mixed`, seed 32: 0.46 m and 1.4 deg after
  // 77 m, chi2 35 and 43). A false loop is a registration's wrong minimum; a second, independent
  // one agreeing with it is unlikely. So two disputed loops that agree with each other over the
  // short odometry between their ends are both kept, if the graph's sigmas would allow each
  // were they 2x larger (chi2 within 4x the limit): a registration's wrong minimum metres away
  // stays refused even when the next one repeats it.
  if (record.chi2 > kLoopPairMaxGraphChi2Factor * config_.loop_max_chi2) return false;
  const RelativePose& loop = record.attempt.loop;
  std::optional<std::size_t> best;
  double best_chi2 = config_.loop_max_chi2;
  for (const std::size_t i : disputed_loops_) {
    const LoopRecord& earlier = attempts_[i];
    if (loop.to - earlier.attempt.loop.to > kLoopPairKeyframes) continue;
    const double chi2 = graph_.loopPairChi2(earlier.attempt.loop, loop);
    if (chi2 <= best_chi2) {
      best = i;
      best_chi2 = chi2;
    }
  }
  if (!best) return false;
  LoopRecord& earlier = attempts_[*best];
  graph_.addLoop(earlier.attempt.loop);
  graph_.addLoop(loop);
  graph_.optimize();
  std::erase(disputed_loops_, *best);
  earlier.attempt.accepted = true;
  earlier.attempt.note = fmt::format(
      "accepted with the loop at keyframe {}, which agrees with it (pair chi2 {:.1f}), though "
      "the graph disputed both",
      loop.to, best_chi2);
  record.attempt.note = fmt::format(
      "accepted with the loop at keyframe {}, which agrees with it (pair chi2 {:.1f}); chi2 "
      "{:.1f} against the graph",
      earlier.attempt.loop.to, best_chi2, record.chi2);
  logger().info(
      "loops at keyframes {} and {} agree (pair chi2 {:.1f}) though the graph "
      "disputed them (chi2 {:.1f} and {:.1f}): both kept, the odometry drifted more than "
      "mapping.odometry_sigma_* allow",
      earlier.attempt.loop.to, loop.to, best_chi2, earlier.chi2, record.chi2);
  return true;
}

MappingThread::MappingThread(const MappingConfig& config, const OdometryConfig& odometry,
                             const KeyframeStore& store, MappingThreadOptions options)
    : mapper_(config, odometry, store, verifyLoop, options.gnss),
      options_(std::move(options)),
      worker_([this] { work(); }) {}

MappingThread::~MappingThread() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void MappingThread::addKeyframe(std::size_t id, double t_s, const lie::SE3& T_odom_body,
                                std::uint64_t segment) {
  push(KeyframeMessage{id, t_s, T_odom_body, segment});
}

void MappingThread::addGnssFix(const GnssFix& fix) { push(fix); }

void MappingThread::push(Message message) {
  {
    const std::lock_guard lock(mutex_);
    queue_.push_back(std::move(message));
  }
  wake_.notify_all();
}

void MappingThread::work() {
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, everything handled
    Message message = std::move(queue_.front());
    queue_.pop_front();
    if (error_) continue;  // drain; the first error is reported by finish()
    lock.unlock();
    try {
      if (const auto* keyframe = std::get_if<KeyframeMessage>(&message)) {
        mapper_.addKeyframe(keyframe->id, keyframe->t_s, keyframe->T_odom_body, keyframe->segment);
        publish(keyframe->id);
      } else {
        mapper_.addGnssFix(std::get<GnssFix>(message));
      }
    } catch (...) {
      lock.lock();
      error_ = std::current_exception();
      snapshot_ready_.notify_all();
      continue;
    }
    lock.lock();
  }
}

void MappingThread::publish(std::size_t id) {
  if (options_.after_keyframe) options_.after_keyframe(mapper_);
  if (options_.snapshot_keyframes == 0) return;
  const std::vector<lie::SE3>& poses = mapper_.graph().poses();
  const std::size_t count = std::min(options_.snapshot_keyframes, poses.size());
  GraphSnapshot snapshot{
      .keyframe = id, .poses_T_map_body = std::vector<lie::SE3>(poses.end() - count, poses.end())};
  {
    const std::lock_guard lock(mutex_);
    snapshots_.push_back(std::move(snapshot));
  }
  snapshot_ready_.notify_all();
}

std::optional<GraphSnapshot> MappingThread::waitForSnapshot(std::size_t keyframe) {
  if (options_.snapshot_keyframes == 0)
    throw std::logic_error("MappingThread::waitForSnapshot: snapshots are off");
  std::unique_lock lock(mutex_);
  snapshot_ready_.wait(lock, [&] {
    return error_ || (!snapshots_.empty() && snapshots_.back().keyframe >= keyframe);
  });
  while (!snapshots_.empty() && snapshots_.front().keyframe < keyframe) snapshots_.pop_front();
  if (snapshots_.empty() || snapshots_.front().keyframe != keyframe) return std::nullopt;
  GraphSnapshot snapshot = std::move(snapshots_.front());
  snapshots_.pop_front();
  return snapshot;
}

Mapper& MappingThread::finish(const lie::SO3& R_level_map) {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
  if (error_) std::rethrow_exception(error_);
  if (!finished_) {
    finished_ = true;
    mapper_.finish(R_level_map);
  }
  return mapper_;
}

}  // namespace taiga::mapping
