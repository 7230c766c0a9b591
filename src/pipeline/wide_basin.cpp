#include "wide_basin.hpp"

#include <algorithm>
#include <chrono>

#include "taiga/core/log.hpp"
#include "taiga/core/percentile.hpp"
#include "taiga/registration/correlative_search.hpp"
#include "taiga/registration/kdtree.hpp"

namespace taiga::pipeline {
namespace {

/// Ok scans whose overlap is the yardstick.
constexpr std::size_t kRecentScans = 10;
constexpr std::size_t kMinRecent = 3;
/// A registration overlapping the map less than this share of the recent median searches.
constexpr double kSearchBelowRecent = 0.85;
/// A searched registration replaces the first only when it overlaps the map this much better:
/// a near tie is the same basin seen through noise, and the prediction is information too.
constexpr double kClearlyBetter = 1.1;
/// Without a yardstick, the share of a scan that must lie on the map for a searched
/// registration to count (a map seeded by a sliver of a scan offers no basin worth choosing).
constexpr double kMinOverlapWithoutHistory = 0.4;
/// Starts proposed by the correlative search.
constexpr std::size_t kStarts = 3;
/// Two registrations farther apart than this are distinct solutions, not one basin.
constexpr double kDistinct_m = 0.3;
constexpr double kDistinct_deg = 3.0;

bool distinct(const lie::SE3& a, const lie::SE3& b) {
  const registration::Separation apart = registration::separation(a, b);
  return apart.m > kDistinct_m || apart.deg > kDistinct_deg;
}

}  // namespace

WideBasin::WideBasin(const OdometryConfig& config)
    // A point on a surface lies within about one map spacing of the map's points when the pose
    // is right; 8 deg off, a stem 3 m away is already 0.4 m off.
    : overlap_distance_m_(1.5 * config.local_map_voxel_m),
      degenerate_condition_(config.degenerate_condition) {}

double WideBasin::overlap(const std::vector<Eigen::Vector3d>& source, const LocalMap& map,
                          const lie::SE3& T_odom_body) const {
  return registration::agreement(source, map.nearest(), T_odom_body, overlap_distance_m_).share;
}

registration::RegistrationResult WideBasin::widen(const std::vector<Eigen::Vector3d>& source,
                                                  const lie::SE3& guess_T_odom_body,
                                                  registration::RegistrationResult first,
                                                  const LocalMap& map, const HealthMonitor& health,
                                                  const Align& align) {
  const bool established = health.hasYardstick() && recent_overlaps_.size() >= kMinRecent;
  // Without a yardstick the monitor judges the fitness against max_fitness_m2 alone.
  const auto suspect = [&](const registration::RegistrationResult& r) {
    return health.registrationSuspect(r.fitness_m2, inlierShare(r, source.size()));
  };
  last_overlap_ = overlap(source, map, first.T_target_source);
  if (established && first.converged && !suspect(first)) {
    const std::vector<double> recent(recent_overlaps_.begin(), recent_overlaps_.end());
    if (last_overlap_ >= kSearchBelowRecent * percentile(recent, 50.0)) return first;
  }
  const double first_overlap = last_overlap_;
  registration::RegistrationResult best = std::move(first);
  const auto search_start = std::chrono::steady_clock::now();
  const std::vector<registration::CorrelativeCandidate> starts = registration::correlativeSearch(
      source, map.occupancy(registration::CorrelativeWindow{}.voxel_m), guess_T_odom_body, {},
      kStarts);
  const double search_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - search_start)
          .count();
  struct Refined {
    registration::RegistrationResult result;
    double overlap;
  };
  std::vector<Refined> refined;
  for (const registration::CorrelativeCandidate& start : starts) {
    registration::RegistrationResult candidate = align(start.T_target_source);
    // A partial scan makes no candidate look normal; a degenerate one (a sliver, a field) leaves
    // the search free to slide it a metre along what it does not constrain.
    if (suspect(candidate) || candidate.hessian_condition > degenerate_condition_) continue;
    const double candidate_overlap = overlap(source, map, candidate.T_target_source);
    if (!established && candidate_overlap < kMinOverlapWithoutHistory) continue;
    refined.push_back({std::move(candidate), candidate_overlap});
  }
  const auto winner =
      std::max_element(refined.begin(), refined.end(),
                       [](const auto& a, const auto& b) { return a.overlap < b.overlap; });
  if (winner != refined.end()) {
    // The winner must stand out from the first result and from every distinct rival: a scan
    // that fits several places about as well (a sliver, a row of like stems) is ambiguous, and
    // the prediction then stays the better guess.
    double rival_overlap = first_overlap;
    for (const Refined& r : refined) {
      if (distinct(r.result.T_target_source, winner->result.T_target_source))
        rival_overlap = std::max(rival_overlap, r.overlap);
    }
    if (winner->overlap > kClearlyBetter * rival_overlap) {
      last_overlap_ = winner->overlap;
      best = std::move(winner->result);
    }
  }
  if (!best.converged) {
    // From a start far off, NDT may use up its iterations short of the minimum, or stop where
    // the Hessian is not yet positive definite, and the lidar factor rejects that: it goes on
    // from where it stopped.
    registration::RegistrationResult again = align(best.T_target_source);
    if (again.converged) {
      last_overlap_ = overlap(source, map, again.T_target_source);
      best = std::move(again);
    }
  }
  logger().debug("wide-basin search: {} starts in {:.1f} ms, overlap {:.2f} -> {:.2f}",
                 starts.size(), search_ms, first_overlap, last_overlap_);
  return best;
}

void WideBasin::rememberLast() {
  recent_overlaps_.push_back(last_overlap_);
  while (recent_overlaps_.size() > kRecentScans) recent_overlaps_.pop_front();
}

}  // namespace taiga::pipeline
