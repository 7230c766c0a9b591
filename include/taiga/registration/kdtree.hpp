#pragma once
// A 3D kd-tree over a copy of the points (nanoflann, built single-threaded, so queries are
// deterministic), and the thesis fitness score computed with it.

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "taiga/lie/se3.hpp"

namespace taiga::registration {

class KdTree {
 public:
  explicit KdTree(std::span<const Eigen::Vector3d> points);
  ~KdTree();
  KdTree(KdTree&&) noexcept;
  KdTree& operator=(KdTree&&) noexcept;

  std::size_t size() const;
  const std::vector<Eigen::Vector3d>& points() const;
  /// Up to k nearest points to `query`, closest first; returns how many were written.
  std::size_t knn(const Eigen::Vector3d& query, std::size_t k, std::size_t* indices,
                  double* squared_distances_m2) const;
  /// The nearest point; false for an empty tree.
  bool nearest(const Eigen::Vector3d& query, std::size_t& index, double& squared_distance_m2) const;
  /// The nearest point if it lies within max_distance_m (inclusive): the same point as nearest(),
  /// but the search stops at that radius, so a query far from every point costs little.
  /// `hint`, when not kNoHint, is a point index; the search then starts from its distance (if
  /// within the radius) instead of the radius: the same distance found, faster when the hint
  /// is near (e.g. the previous query's nearest point, for queries in spatial order).
  bool nearestWithin(const Eigen::Vector3d& query, double max_distance_m, std::size_t& index,
                     double& squared_distance_m2, std::size_t hint = kNoHint) const;
  static constexpr std::size_t kNoHint = static_cast<std::size_t>(-1);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// How well T_target_source * source lies on the target: the thesis fitness score (below) and
/// the share of the source points within max_distance_m of a target point (the overlap).
struct Agreement {
  double fitness_m2 = 0.0;  ///< NaN when no point is within max_distance_m
  double share = 0.0;       ///< 0..1
};
Agreement agreement(std::span<const Eigen::Vector3d> source, const KdTree& target,
                    const lie::SE3& T_target_source, double max_distance_m);

/// Thesis fitness score: mean over the source points of the squared distance (m^2) from
/// T_target_source * p to the closest target point, counting only distances below
/// max_distance_m. NaN when no point counts. Parallel, deterministic.
double fitnessScore(std::span<const Eigen::Vector3d> source, const KdTree& target,
                    const lie::SE3& T_target_source,
                    double max_distance_m = std::numeric_limits<double>::infinity());

}  // namespace taiga::registration
