#pragma once
// A brute-force search over heading and horizontal position, for guesses a local method cannot
// be trusted from (lidar-only odometry at low scan rates: turns of 50 deg and steps of a metre
// between scans).
//
// NDT and GICP converge to the nearest basin of their cost; from a guess 20 deg or a metre off
// they can settle in a wrong one. Here every pose of a grid around the guess (yaw about the
// target's vertical through the guess's position, and x, y in the target frame; roll, pitch and
// height as guessed) is scored by the share of source points that fall into a voxel the target
// occupies, a correlative scan matcher in the sense of Olson (2009, "Real-time correlative scan
// matching") without the likelihood blur: the grid's steps are finer than its voxels, so the
// right pose scores high wherever it lies between them. Stems are vertical, so the score
// tolerates the few degrees of roll and pitch a prediction may be off. The best distinct poses
// are returned for a local method to refine and an overlap test to choose from.

#include <Eigen/Core>
#include <span>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/registration/voxel_index.hpp"

namespace taiga::registration {

struct CorrelativeWindow {
  double yaw_half_deg = 50.0;  ///< deg, searched on each side of the guess
  double yaw_step_deg = 2.0;
  double xy_half_m = 1.0;  ///< m, searched on each side of the guess, in x and in y
  double xy_step_m = 0.2;
  double voxel_m = 0.5;           ///< occupancy voxel edge
  std::size_t max_source = 1500;  ///< source points scored (an even subsample)
};

/// The voxels that target points occupy, at one edge length.
class Occupancy {
 public:
  Occupancy(std::span<const Eigen::Vector3d> target, double voxel_m);
  bool occupied(const Eigen::Vector3d& p) const { return index_.find(voxelOf(p, inverse_m_)) >= 0; }

 private:
  double inverse_m_;
  VoxelIndex index_;
};

struct CorrelativeCandidate {
  lie::SE3 T_target_source;
  double score = 0.0;  ///< share of the scored source points in occupied voxels, 0..1
};

/// The best `max_candidates` poses of the window, best first, each farther than two grid steps
/// (in yaw or in position) from every better one.
std::vector<CorrelativeCandidate> correlativeSearch(std::span<const Eigen::Vector3d> source,
                                                    const Occupancy& target,
                                                    const lie::SE3& guess_T_target_source,
                                                    const CorrelativeWindow& window,
                                                    std::size_t max_candidates);

}  // namespace taiga::registration
