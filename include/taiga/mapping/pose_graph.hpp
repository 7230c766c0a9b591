#pragma once
// The mapping graph of thesis 3.1.2: one node per keyframe (T_map_body), consecutive keyframes
// joined by the odometry's relative pose, loop closures as further relative poses, and absolute
// position factors (GNSS, issue 9) through addPosition(). Solved with Ceres when a loop or an
// absolute factor arrives; in between, a new keyframe is placed by chaining the odometry onto
// the corrected pose of the previous one.
//
// Gauge: without absolute position factors the first keyframe is held fixed, so the map frame
// is the odom frame at the first keyframe (docs/frames.md). GNSS factors (addGnss, backend/
// gnss_factor.hpp) relate the map to ENU through the estimated T_enu_map (yaw and translation),
// so they do not fix the map frame: with them the first keyframe stays fixed too, otherwise the
// map frame and T_enu_map could slide together (a 4-DoF null space) and noisy GNSS heights
// could tilt the whole map away from gravity.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "taiga/core/mapping_config.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::mapping {

/// A relative pose between two keyframes: T_from_to maps points of `to`'s body frame into
/// `from`'s; covariance in the right-perturbation tangent [rho (m); theta (rad)] of T_from_to.
struct RelativePose {
  std::size_t from = 0;
  std::size_t to = 0;
  lie::SE3 T_from_to;
  lie::Matrix6 covariance = lie::Matrix6::Identity();
};

/// A GNSS fix attached to a keyframe (backend/gnss_factor.hpp): the antenna at the fix time in
/// the keyframe's body frame, and the fix in local ENU with its covariance.
struct GnssObservation {
  std::size_t keyframe = 0;
  Eigen::Vector3d d_body = Eigen::Vector3d::Zero();                 ///< m
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();                  ///< m
  Eigen::Matrix3d covariance_enu_m2 = Eigen::Matrix3d::Identity();  ///< m^2
  double huber_sigmas = 0.0;  ///< > 0: Huber kernel beyond that many (whitened) sigmas
  /// Scales the (robustified) cost, e.g. 1/f for errors correlated in time (gnss_fusion.hpp):
  /// the Huber threshold stays in sigmas of the reported covariance.
  double weight = 1.0;
};

class PoseGraph {
 public:
  explicit PoseGraph(const MappingConfig& config);

  /// Appends a keyframe at its odometry pose and returns its index (0, 1, ...). From the
  /// second on, an odometry factor joins it to the previous keyframe, with the sigmas of
  /// MappingConfig grown with the distance between them; across a change of the odometry's map
  /// `segment` (it was lost and started over, placed by dead reckoning) that factor carries no
  /// weight (kBridgeSigma_m / _rad): only a relocalization or GNSS ties the segments together.
  std::size_t addKeyframe(const lie::SE3& T_odom_body, std::uint64_t segment = 0);
  /// The odometry's map segment of a keyframe.
  std::uint64_t segment(std::size_t keyframe) const { return segments_[keyframe]; }
  static constexpr double kBridgeSigma_m = 1e4;
  static constexpr double kBridgeSigma_rad = 1e2;
  /// A loop closure factor (from < to).
  void addLoop(const RelativePose& loop);
  /// Adds `loop` and re-optimizes when the loop agrees with the graph: when it raises the
  /// optimal cost by at most max_chi2 / 2. A correct loop adds about its innovation's squared
  /// Mahalanobis distance against the odometry's accumulated uncertainty; a false one bends the
  /// graph and costs far more. Returns that chi^2; the graph is unchanged when it is above.
  double addLoopIfConsistent(const RelativePose& loop, double max_chi2);
  /// How well two loops agree with each other, whatever the long stretch of odometry between
  /// their ends says (pairwise consistency, after Mangelson et al. 2018, "PCM"): chi^2 (6 degrees
  /// of freedom) of the cycle first.from -> first.to -> second.to -> second.from -> first.from,
  /// whose odometry is only the short stretches between the loops' ends. Infinity when such a
  /// stretch crosses map segments.
  double loopPairChi2(const RelativePose& first, const RelativePose& second) const;
  /// An absolute position of a keyframe in the map frame (m) with its covariance (m^2);
  /// `huber_sigmas` > 0 makes the factor robust beyond that many sigmas.
  void addPosition(std::size_t keyframe, const Eigen::Vector3d& p_map,
                   const Eigen::Matrix3d& covariance, double huber_sigmas = 0.0);

  /// Starts (or resets) the estimate of T_enu_map; its roll and pitch are dropped. Needed
  /// before addGnss().
  void setEnuMap(const lie::SE3& T_enu_map);
  /// The current T_enu_map (yaw and translation), once set.
  const std::optional<lie::SE3>& enuMap() const { return T_enu_map_; }
  /// A GNSS factor; the graph must have T_enu_map (setEnuMap) and the keyframe.
  void addGnss(const GnssObservation& observation);
  const std::vector<GnssObservation>& gnss() const { return gnss_; }
  /// Whitened residual norm of each GNSS factor at the current poses and T_enu_map (in
  /// sigmas of the fix's covariance; the Huber kernel down-weights those above huber_sigmas).
  std::vector<double> gnssWhitenedResiduals() const;

  /// Turns the whole map (every keyframe pose, the absolute positions, T_enu_map with its roll
  /// and pitch dropped) by R_new_old about the map origin: the odometry's final estimate of its
  /// frame's tilt levels the map (mapping/mapper.hpp, finish). Relative factors are unchanged,
  /// so is the cost without GNSS.
  void rotateMap(const lie::SO3& R_new_old);

  /// Solves for every keyframe pose; returns the final cost.
  double optimize();
  /// The cost at the current poses after the last optimize() (0 before); keyframes added since
  /// sit on their odometry factors and add nothing.
  double cost() const { return cost_; }
  /// Whether factors that change the optimum (GNSS) were added since the last optimize().
  bool hasUnsolvedFactors() const { return unsolved_; }

  std::size_t size() const { return odometry_poses_.size(); }
  /// The corrected pose of a keyframe.
  const lie::SE3& pose(std::size_t keyframe) const { return poses_[keyframe]; }
  const std::vector<lie::SE3>& poses() const { return poses_; }
  /// The pose the odometry gave the keyframe.
  const lie::SE3& odometryPose(std::size_t keyframe) const { return odometry_poses_[keyframe]; }
  /// Odometry path length from the first keyframe to `keyframe`, m.
  double pathLength(std::size_t keyframe) const { return path_lengths_m_[keyframe]; }
  const std::vector<RelativePose>& loops() const { return loops_; }

 private:
  struct Position {
    std::size_t keyframe;
    Eigen::Vector3d p_map;
    Eigen::Matrix3d covariance;
    double huber_sigmas;
  };
  RelativePose odometryBetween(std::size_t from, std::size_t to) const;

  MappingConfig config_;
  std::vector<lie::SE3> odometry_poses_;
  std::vector<std::uint64_t> segments_;
  std::vector<lie::SE3> poses_;
  std::vector<double> path_lengths_m_;
  std::vector<RelativePose> loops_;
  std::vector<Position> positions_;
  std::vector<GnssObservation> gnss_;
  std::optional<lie::SE3> T_enu_map_;
  bool unsolved_ = false;
  double cost_ = 0.0;
};

}  // namespace taiga::mapping
