#include "taiga/mapping/relocalization.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/mapping/loop_closure.hpp"
#include "taiga/registration/correlative_search.hpp"
#include "taiga/registration/kdtree.hpp"
#include "taiga/registration/registration.hpp"

namespace taiga::mapping {
namespace {

/// Starts from the correlative search that NDT refines.
constexpr std::size_t kStarts = 4;
/// The share of the current keyframe's points that must lie on the submap: a keyframe seen from
/// where the map was made overlaps it mostly; a wrong basin in a forest 0.1-0.4 (the wide basin's
/// measurements, docs/odometry.md).
constexpr double kMinOverlap = 0.5;
/// The winner must overlap this much more than every distinct rival.
constexpr double kClearlyBetter = 1.15;
/// Two refinements farther apart than this are distinct solutions, not one basin.
constexpr double kDistinct_m = 0.3;
constexpr double kDistinct_deg = 3.0;

struct Refined {
  registration::RegistrationResult registration;
  double overlap = 0.0;
};

}  // namespace

std::optional<std::size_t> findRelocalizationCandidate(const PoseGraph& graph, std::size_t current,
                                                       const Attached& attached,
                                                       const MappingConfig& config) {
  const Eigen::Vector3d& p_current = graph.pose(current).translation();
  std::optional<std::size_t> best;
  double best_m = config.loop_max_search_radius_m;
  for (std::size_t k = 0; k < current; ++k) {
    if (!attached(k)) continue;
    const double distance_m = (graph.pose(k).translation() - p_current).norm();
    if (distance_m <= best_m) {
      best = k;
      best_m = distance_m;
    }
  }
  return best;
}

RelocalizationAttempt relocalize(const PoseGraph& graph, const KeyframeStore& store,
                                 std::size_t current, std::size_t candidate,
                                 const Attached& attached, const MappingConfig& config,
                                 const OdometryConfig& odometry) {
  RelocalizationAttempt attempt{.current = current, .candidate = candidate};
  const std::shared_ptr<const PointCloud> source = store.registrationCloud(current);
  const std::size_t half = static_cast<std::size_t>(config.loop_submap_keyframes);
  const std::vector<Eigen::Vector3d> submap =
      submapIn(graph, store, candidate, candidate >= half ? candidate - half : 0,
               std::min(candidate + half, current - 1), attached);
  const lie::SE3 guess = graph.pose(candidate).inverse() * graph.pose(current);

  // Wide: the search; then NDT from its best distinct starts.
  const registration::CorrelativeWindow window{.yaw_half_deg = config.relocalization_search_deg,
                                               .yaw_step_deg = 2.0,
                                               .xy_half_m = config.relocalization_search_m,
                                               .xy_step_m = 0.25};
  const registration::Occupancy occupancy(submap, window.voxel_m);
  const registration::KdTree tree(submap);
  registration::RegistrationConfig ndt = loopRegistrationConfig(odometry);
  ndt.compute_fitness = false;  // below, without the points the submap does not cover
  std::vector<Refined> refined;
  for (const registration::CorrelativeCandidate& start :
       registration::correlativeSearch(source->positions, occupancy, guess, window, kStarts)) {
    registration::RegistrationResult r =
        registration::registerClouds(source->positions, submap, start.T_target_source, ndt);
    // Fitness within a few coarse cells, as the odometry's (reported, not judged: the keyframe
    // may stand metres from the submap's keyframes and see what they did not, so the fitness
    // measures the submap's coverage as much as the alignment; the overlap and the rivals judge).
    const registration::Agreement near = registration::agreement(
        source->positions, tree, r.T_target_source, 2.0 * odometry.coarsestNdtResolutionM());
    r.fitness_m2 = near.fitness_m2;
    const double overlap =
        registration::agreement(source->positions, tree, r.T_target_source, odometry.voxel_size_m)
            .share;
    refined.push_back({std::move(r), overlap});
  }
  if (refined.empty()) {
    attempt.note = "no start found";
    return attempt;
  }
  std::sort(refined.begin(), refined.end(),
            [](const Refined& a, const Refined& b) { return a.overlap > b.overlap; });
  const Refined& best = refined.front();
  for (const Refined& other : refined) {
    const registration::Separation apart = registration::separation(
        best.registration.T_target_source, other.registration.T_target_source);
    if (apart.m > kDistinct_m || apart.deg > kDistinct_deg) {
      attempt.rival_overlap = other.overlap;
      break;
    }
  }
  const registration::RegistrationResult& r = best.registration;
  attempt.overlap = best.overlap;
  attempt.fitness_m2 = r.fitness_m2;
  const registration::Separation correction = registration::separation(guess, r.T_target_source);
  attempt.correction_m = correction.m;
  attempt.correction_deg = correction.deg;
  attempt.link =
      RelativePose{candidate, current, r.T_target_source, loopCovariance(odometry, r.fitness_m2)};

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
