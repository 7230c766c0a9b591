#include "taiga/mapping/loop_closure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "taiga/core/angles.hpp"
#include "taiga/registration/registration.hpp"

namespace taiga::mapping {
std::optional<LoopCandidate> findLoopCandidate(const PoseGraph& graph, std::size_t current,
                                               const MappingConfig& config) {
  const auto excluded = static_cast<std::size_t>(config.loop_exclude_recent_keyframes);
  if (current < excluded) return std::nullopt;
  const Eigen::Vector3d& p_current = graph.pose(current).translation();
  std::optional<LoopCandidate> best;
  for (std::size_t k = 0; k + excluded <= current; ++k) {
    const double radius_m = std::min(
        config.loop_search_radius_m +
            config.loop_radius_growth_m_per_m * (graph.pathLength(current) - graph.pathLength(k)),
        config.loop_max_search_radius_m);
    const double distance_m = (graph.pose(k).translation() - p_current).norm();
    if (distance_m <= radius_m && (!best || distance_m < best->distance_m))
      best = LoopCandidate{k, distance_m, radius_m};
  }
  return best;
}

std::vector<Eigen::Vector3d> submapIn(const PoseGraph& graph, const KeyframeStore& store,
                                      std::size_t frame, std::size_t first, std::size_t last,
                                      const std::function<bool(std::size_t)>& keep) {
  const lie::SE3 T_frame_map = graph.pose(frame).inverse();
  std::vector<std::shared_ptr<const PointCloud>> clouds;
  std::size_t submap_points = 0;
  for (std::size_t k = first; k <= last; ++k) {
    clouds.push_back(keep(k) ? store.registrationCloud(k) : nullptr);
    if (clouds.back()) submap_points += clouds.back()->size();
  }
  // Sized once: grown by doubling it would leave freed blocks of up to twice its size behind in
  // the mapping thread's heap at every attempt.
  std::vector<Eigen::Vector3d> submap_in_frame;
  submap_in_frame.reserve(submap_points);
  for (std::size_t k = first; k <= last; ++k) {
    if (!clouds[k - first]) continue;
    const lie::SE3 T_frame_k = T_frame_map * graph.pose(k);
    for (const Eigen::Vector3d& p_k : clouds[k - first]->positions)
      submap_in_frame.push_back(T_frame_k * p_k);
  }
  return submap_in_frame;
}

registration::RegistrationConfig loopRegistrationConfig(const OdometryConfig& odometry) {
  // The odometry's NDT passes (registrationConfigFor), after one at 3x its coarsest cells, all
  // neighbouring cells scored: the guess may be off by the drift since the candidate, and a
  // coarser pass widens the basin. NDT whatever the odometry's method, for that coarse pass.
  registration::RegistrationConfig registration_config =
      registration::registrationConfigFor(odometry);
  registration_config.method = registration::Method::kNdt;
  std::vector<double>& coarse_m = registration_config.ndt.coarse_resolutions_m;
  const double coarsest_m =
      coarse_m.empty() ? registration_config.ndt.resolution_m : coarse_m.front();
  coarse_m.insert(coarse_m.begin(), 3.0 * coarsest_m);
  registration_config.ndt.search = registration::NeighbourSearch::kDirect7;
  return registration_config;
}

lie::Matrix6 loopCovariance(const OdometryConfig& odometry, double fitness_m2) {
  // Thesis Eq. 36 as for the odometry's lidar factor, with the heading sigma on all three
  // rotation axes: the odometry chain between the keyframes holds roll and pitch (gravity).
  const LidarSigmas sigma = odometry.lidarSigmas(fitness_m2);
  lie::Vector6 variances;
  variances << lie::Vector3::Constant(sigma.translation_m * sigma.translation_m),
      lie::Vector3::Constant(sigma.heading_rad * sigma.heading_rad);
  return variances.asDiagonal().toDenseMatrix();
}

LoopAttempt verifyLoop(const PoseGraph& graph, const KeyframeStore& store, std::size_t current,
                       const LoopCandidate& candidate, const MappingConfig& config,
                       const OdometryConfig& odometry) {
  LoopAttempt attempt{.current = current, .candidate = candidate};
  const std::shared_ptr<const PointCloud> source = store.registrationCloud(current);

  // The candidate's submap: its neighbours (never the recent keyframes) in its body frame.
  const std::size_t half = static_cast<std::size_t>(config.loop_submap_keyframes);
  const std::size_t first = candidate.keyframe >= half ? candidate.keyframe - half : 0;
  const std::size_t last =
      std::min(candidate.keyframe + half,
               current - static_cast<std::size_t>(config.loop_exclude_recent_keyframes));
  const std::vector<Eigen::Vector3d> submap_in_candidate =
      submapIn(graph, store, candidate.keyframe, first, last, [](std::size_t) { return true; });
  const lie::SE3 guess_T_candidate_current =
      graph.pose(candidate.keyframe).inverse() * graph.pose(current);
  attempt.registration =
      registration::registerClouds(source->positions, submap_in_candidate,
                                   guess_T_candidate_current, loopRegistrationConfig(odometry));
  const registration::RegistrationResult& r = attempt.registration;
  const lie::Vector6 correction = (guess_T_candidate_current.inverse() * r.T_target_source).Log();
  attempt.correction_m = correction.head<3>().norm();
  attempt.correction_deg = correction.tail<3>().norm() / kRadPerDeg;

  if (!r.converged) {
    attempt.note = "registration did not converge: " + r.reason;
  } else if (!(r.fitness_m2 <= config.loop_max_fitness_m2)) {
    attempt.note =
        fmt::format("fitness {:.3f} m^2 above {:.3f}", r.fitness_m2, config.loop_max_fitness_m2);
  } else if (attempt.correction_m > candidate.search_radius_m ||
             attempt.correction_deg > config.loop_max_rotation_deg) {
    attempt.note = fmt::format("correction {:.2f} m / {:.2f} deg beyond {:.2f} m / {:.1f} deg",
                               attempt.correction_m, attempt.correction_deg,
                               candidate.search_radius_m, config.loop_max_rotation_deg);
  } else {
    attempt.accepted = true;
  }
  attempt.loop = RelativePose{candidate.keyframe, current, r.T_target_source,
                              loopCovariance(odometry, r.fitness_m2)};
  return attempt;
}

}  // namespace taiga::mapping
