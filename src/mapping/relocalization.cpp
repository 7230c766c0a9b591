#include "taiga/mapping/relocalization.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/core/log.hpp"
#include "taiga/mapping/loop_closure.hpp"
#include "taiga/registration/correlative_search.hpp"
#include "taiga/registration/kdtree.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/registration/registration.hpp"

namespace taiga::mapping {
namespace {

/// Starts from the correlative search that NDT refines.
constexpr std::size_t kStarts = 4;
/// The share of the current keyframe's above-ground points that must lie on the submap: a keyframe
/// seen from where the map was made overlaps it mostly; a wrong basin in a forest 0.1-0.4 (the wide
/// basin's measurements, docs/odometry.md).
constexpr double kMinOverlap = 0.5;
/// The winner must overlap this much more than every distinct rival.
constexpr double kClearlyBetter = 1.15;
/// Two refinements farther apart than this are distinct solutions, not one basin.
constexpr double kDistinct_m = 0.3;
constexpr double kDistinct_deg = 3.0;

/// Above-ground points: stems, branches, crowns. The ground lies within a few decimetres of any
/// other ground at almost any pose (a synthetic forest's other seed: 63 % of a keyframe "on the
/// map"), so the overlap counts only what stands on it.
constexpr double kColumn_m = 2.0;  ///< the ground is the lowest point of such a column
constexpr double kAboveGround_m = 0.5;
constexpr std::size_t kMinAboveGround = 200;  ///< fewer: an open field, nothing to find it by

struct Refined {
  registration::RegistrationResult registration;
  double overlap = 0.0;
  std::size_t candidate = 0;  ///< the keyframe whose submap it was registered in
  lie::SE3 T_map_current;
};

/// Source points NDT refines each start with (an even sample): a link needs centimetres, not the
/// whole keyframe, and each start costs a registration.
constexpr std::size_t kNdtSourcePoints = 4000;

std::vector<Eigen::Vector3d> evenSample(const std::vector<Eigen::Vector3d>& points,
                                        std::size_t count) {
  if (points.size() <= count) return points;
  std::vector<Eigen::Vector3d> sample;
  sample.reserve(count);
  for (std::size_t i = 0; i < count; ++i) sample.push_back(points[i * points.size() / count]);
  return sample;
}

/// The loop closure's NDT passes, coarse to fine, with their cells built once for every start.
class NdtPasses {
 public:
  NdtPasses(std::span<const Eigen::Vector3d> target, const registration::NdtConfig& config)
      : config_(config) {
    for (const double resolution_m : config.coarse_resolutions_m)
      targets_.push_back(
          registration::NdtTarget::fromPoints(target, resolution_m, config.cellsAt(resolution_m)));
    targets_.push_back(registration::NdtTarget::fromPoints(target, config.resolution_m, config));
  }

  registration::RegistrationResult align(std::span<const Eigen::Vector3d> source,
                                         lie::SE3 guess) const {
    registration::RegistrationResult result;
    int iterations = 0;
    for (const registration::NdtTarget& target : targets_) {
      result = registration::alignNdt(source, target, guess, config_);
      iterations += result.iterations;
      if (result.num_inliers == 0) break;
      guess = result.T_target_source;
    }
    result.iterations = iterations;
    return result;
  }

 private:
  registration::NdtConfig config_;
  std::vector<registration::NdtTarget> targets_;
};

/// The correlative search over the whole window at 1 m voxels, 0.5 m and 4 deg steps, then at
/// 0.5 m voxels, 0.25 m and 2 deg steps around each of its best poses (Olson's multi-resolution
/// search, without its bound): a tenth of the lookups of the fine search over the whole window.
std::vector<registration::CorrelativeCandidate> searchCoarseToFine(
    std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target,
    const lie::SE3& guess, const MappingConfig& config) {
  constexpr std::size_t kCoarseCandidates = 8;
  const registration::CorrelativeWindow coarse{.yaw_half_deg = config.relocalization_search_deg,
                                               .yaw_step_deg = 4.0,
                                               .xy_half_m = config.relocalization_search_m,
                                               .xy_step_m = 0.5,
                                               .voxel_m = 1.0,
                                               .max_source = 1000};
  const registration::CorrelativeWindow fine{
      .yaw_half_deg = 4.0, .yaw_step_deg = 2.0, .xy_half_m = 0.5, .xy_step_m = 0.25};
  const registration::Occupancy coarse_occupancy(target, coarse.voxel_m);
  const registration::Occupancy fine_occupancy(target, fine.voxel_m);
  std::vector<registration::CorrelativeCandidate> found;
  for (const registration::CorrelativeCandidate& near : registration::correlativeSearch(
           source, coarse_occupancy, guess, coarse, kCoarseCandidates)) {
    const std::vector<registration::CorrelativeCandidate> best =
        registration::correlativeSearch(source, fine_occupancy, near.T_target_source, fine, 1);
    found.insert(found.end(), best.begin(), best.end());
  }
  std::sort(found.begin(), found.end(),
            [](const auto& a, const auto& b) { return a.score > b.score; });
  if (found.size() > kStarts) found.resize(kStarts);
  return found;
}

/// The points more than kAboveGround_m above the lowest point of their kColumn_m column (z up:
/// the body frame is gravity-aligned up to the tilt of the rig).
std::vector<Eigen::Vector3d> aboveGround(const std::vector<Eigen::Vector3d>& points) {
  const auto column = [](const Eigen::Vector3d& p) {
    return std::pair{static_cast<long>(std::floor(p.x() / kColumn_m)),
                     static_cast<long>(std::floor(p.y() / kColumn_m))};
  };
  std::map<std::pair<long, long>, double> lowest_z;
  for (const Eigen::Vector3d& p : points) {
    auto [it, inserted] = lowest_z.try_emplace(column(p), p.z());
    if (!inserted) it->second = std::min(it->second, p.z());
  }
  std::vector<Eigen::Vector3d> above;
  for (const Eigen::Vector3d& p : points)
    if (p.z() > lowest_z.at(column(p)) + kAboveGround_m) above.push_back(p);
  return above;
}

}  // namespace

namespace {

/// The attached keyframe before `current` nearest to `p_map` (graph poses), within max_m.
std::optional<std::size_t> nearestAttached(const PoseGraph& graph, const Eigen::Vector3d& p_map,
                                           std::size_t current, const Attached& attached,
                                           double max_m) {
  std::optional<std::size_t> best;
  double best_m = max_m;
  for (std::size_t k = 0; k < current; ++k) {
    if (!attached(k)) continue;
    const double distance_m = (graph.pose(k).translation() - p_map).norm();
    if (distance_m <= best_m) {
      best = k;
      best_m = distance_m;
    }
  }
  return best;
}

}  // namespace

std::optional<std::size_t> findRelocalizationCandidate(const PoseGraph& graph, std::size_t current,
                                                       const Attached& attached,
                                                       const MappingConfig& config) {
  return nearestAttached(graph, graph.pose(current).translation(), current, attached,
                         config.loop_max_search_radius_m);
}

namespace {

/// The candidate's submap: its attached neighbours before `current`, in its frame.
std::vector<Eigen::Vector3d> submapOf(const PoseGraph& graph, const KeyframeStore& store,
                                      std::size_t current, std::size_t candidate,
                                      const Attached& attached, const MappingConfig& config) {
  const std::size_t half = static_cast<std::size_t>(config.loop_submap_keyframes);
  return submapIn(graph, store, candidate, candidate >= half ? candidate - half : 0,
                  std::min(candidate + half, current - 1), attached);
}

/// A keyframe's submap with its search structures, built once per attempt that refines in it;
/// refine() registers the current keyframe from a start T_candidate_current and judges it by its
/// overlap, with its pose in the map frame for comparing rivals from different submaps.
class SubmapRefiner {
 public:
  SubmapRefiner(const PoseGraph& graph, const KeyframeStore& store, std::size_t current,
                std::size_t candidate, const Attached& attached, const MappingConfig& config,
                const OdometryConfig& odometry)
      : candidate_(candidate),
        T_map_candidate_(graph.pose(candidate)),
        odometry_(odometry),
        submap_(submapOf(graph, store, current, candidate, attached, config)),
        tree_(submap_),
        ndt_(submap_, loopRegistrationConfig(odometry).ndt) {}
  SubmapRefiner(const SubmapRefiner&) = delete;
  SubmapRefiner& operator=(const SubmapRefiner&) = delete;

  const std::vector<Eigen::Vector3d>& submap() const { return submap_; }

  /// `sample`: the source's points NDT uses; `standing`: its points above the ground.
  Refined refine(const lie::SE3& start, const PointCloud& source,
                 const std::vector<Eigen::Vector3d>& sample,
                 const std::vector<Eigen::Vector3d>& standing) const {
    registration::RegistrationResult r = ndt_.align(sample, start);
    // Fitness within a few coarse cells, as the odometry's (reported, not judged: the keyframe
    // may stand metres from the submap's keyframes and see what they did not, so the fitness
    // measures the submap's coverage as much as the alignment; the overlap and the rivals judge).
    const registration::Agreement near = registration::agreement(
        source.positions, tree_, r.T_target_source, 2.0 * odometry_.coarsestNdtResolutionM());
    r.fitness_m2 = near.fitness_m2;
    const double overlap =
        registration::agreement(standing, tree_, r.T_target_source, odometry_.voxel_size_m).share;
    const lie::SE3 T_map_current = T_map_candidate_ * r.T_target_source;
    return {std::move(r), overlap, candidate_, T_map_current};
  }

 private:
  std::size_t candidate_;
  lie::SE3 T_map_candidate_;
  const OdometryConfig& odometry_;
  std::vector<Eigen::Vector3d> submap_;
  registration::KdTree tree_;
  NdtPasses ndt_;
};

/// The segment's stems around `current` (found in the full scans of it and up to
/// kConstellationKeyframes before it in its segment, together: one scan of 64 beams shows few
/// whole stems) in its body frame, and the attached map's within loop_max_search_radius_m (each
/// keyframe's, cached, placed by the graph); the motions of the first onto the second
/// (stem_constellation.hpp) are poses T_map_current, level. Not the segment's map frame: dead
/// reckoning through a gap turns it about every axis (a constant angular velocity), and its
/// stems would not stand upright in it; the rig's own z is up to within its tilt.
constexpr std::size_t kConstellationKeyframes = 5;
std::vector<lie::SE3> constellationPoses(const PoseGraph& graph, const KeyframeStore& store,
                                         std::size_t current, const Attached& attached,
                                         const MappingConfig& config,
                                         const KeyframeStemMarks& stems_of) {
  const auto placed = [&](std::size_t k, std::vector<StemMark>& into) {
    for (StemMark mark : stems_of(k)) {
      mark.position_m = graph.pose(k) * mark.position_m;
      into.push_back(mark);
    }
  };
  std::vector<Eigen::Vector3d> segment_points;
  for (std::size_t k = current + 1; k-- > 0 && current - k <= kConstellationKeyframes;) {
    if (graph.segment(k) != graph.segment(current)) break;
    const lie::SE3 T_current_k = graph.pose(current).inverse() * graph.pose(k);
    for (const Eigen::Vector3d& p_k : store.load(k).positions)
      if (p_k.allFinite()) segment_points.push_back(T_current_k * p_k);
  }
  const std::vector<StemMark> source = cloudStemMarks(segment_points);
  std::vector<StemMark> target;
  const Eigen::Vector3d& p_current = graph.pose(current).translation();
  for (std::size_t k = 0; k < current; ++k)
    if (attached(k) &&
        (graph.pose(k).translation() - p_current).norm() <= config.loop_max_search_radius_m)
      placed(k, target);
  const std::vector<StemMark> target_stems = mergeStemMarks(target);
  const std::vector<ConstellationMatch> matches = matchConstellations(source, target_stems);
  logger().debug(
      "relocalization of keyframe {}: {} stems of the segment, {} of the map, {} "
      "matches{}",
      current, source.size(), target_stems.size(), matches.size(),
      matches.empty() ? ""
                      : fmt::format(" (best {} stems, {:.2f} m RMS)", matches.front().inliers,
                                    matches.front().rms_m));
  std::vector<lie::SE3> poses;
  for (const ConstellationMatch& match : matches) poses.push_back(match.T_target_source);
  return poses;
}

}  // namespace

RelocalizationAttempt relocalize(const PoseGraph& graph, const KeyframeStore& store,
                                 std::size_t current, std::size_t candidate,
                                 const Attached& attached, const MappingConfig& config,
                                 const OdometryConfig& odometry,
                                 const KeyframeStemMarks& stems_of) {
  const auto start_time = std::chrono::steady_clock::now();
  RelocalizationAttempt attempt{.current = current, .candidate = candidate};
  const std::shared_ptr<const PointCloud> source = store.registrationCloud(current);
  const lie::SE3 guess = graph.pose(candidate).inverse() * graph.pose(current);
  const std::vector<Eigen::Vector3d> standing = aboveGround(source->positions);
  if (standing.size() < kMinAboveGround) {
    attempt.note =
        fmt::format("{} points above the ground, too few to be found by", standing.size());
    return attempt;
  }

  // The submaps registered in, each built once (several stem matches may share one).
  std::map<std::size_t, SubmapRefiner> refiners;
  const auto refinerOf = [&](std::size_t k) -> const SubmapRefiner& {
    return refiners.try_emplace(k, graph, store, current, k, attached, config, odometry)
        .first->second;
  };
  const std::vector<Eigen::Vector3d> sample = evenSample(source->positions, kNdtSourcePoints);
  // Near dead reckoning: the window search; then NDT from its best distinct starts.
  const SubmapRefiner& at_candidate = refinerOf(candidate);
  std::vector<Refined> refined;
  for (const registration::CorrelativeCandidate& start :
       searchCoarseToFine(source->positions, at_candidate.submap(), guess, config))
    refined.push_back(at_candidate.refine(start.T_target_source, *source, sample, standing));
  // Anywhere within the search radius: where the stems put it, each in its nearest keyframe's
  // submap.
  if (stems_of) {
    for (const lie::SE3& T_map_current :
         constellationPoses(graph, store, current, attached, config, stems_of)) {
      const std::optional<std::size_t> near =
          nearestAttached(graph, T_map_current.translation(), current, attached,
                          std::numeric_limits<double>::infinity());
      if (!near) continue;
      refined.push_back(refinerOf(*near).refine(graph.pose(*near).inverse() * T_map_current,
                                                *source, sample, standing));
    }
  }
  if (refined.empty()) {
    attempt.note = "no start found";
    return attempt;
  }
  std::stable_sort(refined.begin(), refined.end(),
                   [](const Refined& a, const Refined& b) { return a.overlap > b.overlap; });
  const Refined& best = refined.front();
  for (const Refined& other : refined) {
    const registration::Separation apart =
        registration::separation(best.T_map_current, other.T_map_current);
    if (apart.m > kDistinct_m || apart.deg > kDistinct_deg) {
      attempt.rival_overlap = other.overlap;
      break;
    }
  }
  attempt.search_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_time)
          .count();
  const registration::RegistrationResult& r = best.registration;
  attempt.candidate = best.candidate;
  attempt.overlap = best.overlap;
  attempt.fitness_m2 = r.fitness_m2;
  const registration::Separation correction =
      registration::separation(graph.pose(current), best.T_map_current);
  attempt.correction_m = correction.m;
  attempt.correction_deg = correction.deg;
  attempt.link = RelativePose{best.candidate, current, r.T_target_source,
                              loopCovariance(odometry, r.fitness_m2)};

  if (!r.converged) {
    attempt.note = "registration did not converge: " + r.reason;
  } else if (best.overlap < kMinOverlap) {
    attempt.note = fmt::format("{:.0f} % of the points on the map, fewer than {:.0f} %",
                               100.0 * best.overlap, 100.0 * kMinOverlap);
  } else if (best.overlap < kClearlyBetter * attempt.rival_overlap) {
    attempt.note = fmt::format("ambiguous: {:.0f} % of the points on the map, {:.0f} % elsewhere",
                               100.0 * best.overlap, 100.0 * attempt.rival_overlap);
  } else {
    attempt.accepted = true;
  }
  return attempt;
}

}  // namespace taiga::mapping
