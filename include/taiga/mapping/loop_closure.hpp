#pragma once
// Loop closure after thesis Eq. 38, with what the thesis lacked: a search radius that grows with
// the path travelled since the candidate (the drift the odometry may have accumulated, so long
// loops still close) and a consistency check against the graph before a loop is kept.
//
//   candidate: the keyframe nearest to the current one (corrected poses), excluding the most
//              recent loop_exclude_recent_keyframes, within
//              r = min(loop_search_radius_m + loop_radius_growth_m_per_m * path since it,
//                      loop_max_search_radius_m);
//   verify:    the current keyframe's registration cloud is registered (NDT, coarse to fine) to
//              a submap of the candidate and its neighbours, expressed in the candidate's body
//              frame, from the guess the graph gives; rejected on a failed registration, a fitness
//              above loop_max_fitness_m2, or a correction larger than the search radius or
//              loop_max_rotation_deg; else a relative pose with the fitness-scaled covariance of
//              Eq. 36.

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "taiga/core/mapping_config.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/pose_graph.hpp"
#include "taiga/registration/registration.hpp"
#include "taiga/registration/result.hpp"

namespace taiga::mapping {

struct LoopCandidate {
  std::size_t keyframe = 0;
  double distance_m = 0.0;       ///< between the corrected poses
  double search_radius_m = 0.0;  ///< the grown radius it was found within
};

struct LoopAttempt {
  std::size_t current = 0;
  LoopCandidate candidate;
  bool accepted = false;
  std::string note;  ///< why it was rejected
  registration::RegistrationResult registration;
  RelativePose loop;            ///< from = candidate, to = current
  double correction_m = 0.0;    ///< how far the loop moves the current keyframe
  double correction_deg = 0.0;  ///< and how far it turns it
};

/// The nearest admissible keyframe to `current`, if any.
std::optional<LoopCandidate> findLoopCandidate(const PoseGraph& graph, std::size_t current,
                                               const MappingConfig& config);

/// The registration clouds of the keyframes in [first, last] that `keep` admits, in the body
/// frame of keyframe `frame`, at the graph's poses.
std::vector<Eigen::Vector3d> submapIn(const PoseGraph& graph, const KeyframeStore& store,
                                      std::size_t frame, std::size_t first, std::size_t last,
                                      const std::function<bool(std::size_t)>& keep);
/// The odometry's NDT passes after a first one at 3x their coarsest cells (a wider basin).
registration::RegistrationConfig loopRegistrationConfig(const OdometryConfig& odometry);
/// A loop's covariance from its fitness (thesis Eq. 36, the heading sigma on every axis).
lie::Matrix6 loopCovariance(const OdometryConfig& odometry, double fitness_m2);

/// Registers `current` to the candidate's submap and judges the result (see above).
LoopAttempt verifyLoop(const PoseGraph& graph, const KeyframeStore& store, std::size_t current,
                       const LoopCandidate& candidate, const MappingConfig& config,
                       const OdometryConfig& odometry);

}  // namespace taiga::mapping
