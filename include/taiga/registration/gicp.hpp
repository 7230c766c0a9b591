#pragma once
// Generalized ICP after Segal, Haehnel, Thrun, "Generalized-ICP" (RSS 2009), in the form of
// small_gicp (Koide 2024): every point carries a covariance from its k nearest neighbours,
// regularized to a plane (eigenvalues replaced by (eps, 1, 1), Segal Sec. III-B); each source
// point x with its nearest target point y (closer than max_correspondence_distance_m) gives the
// residual r = T x - y with the weight M = (C_y + R C_x R^T)^-1, and Gauss-Newton on the right
// perturbation T * Exp(tau), tau = [rho; theta], minimizes sum r^T M r with
// dr/dtau = R [I, -[x]x] (M held fixed within an iteration, as in Segal and small_gicp).
// Correspondences are searched again at every iteration. Parallel and deterministic (block
// reduction).

#include <Eigen/Core>
#include <span>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/registration/kdtree.hpp"
#include "taiga/registration/result.hpp"

namespace taiga::registration {

struct GicpConfig {
  /// k for the covariances (>= 5). 10 rather than Segal's 20: on the HDL-32E test pair k = 20
  /// left 0.68 deg between GICP and the reference, k = 10 0.12-0.46 deg (docs/registration.md).
  std::size_t num_neighbours = 10;
  double covariance_epsilon = 1e-3;            ///< smallest eigenvalue of a plane covariance, m^2
  double max_correspondence_distance_m = 1.0;  ///< farther pairs are ignored
  int max_iterations = 64;
  double step_epsilon_m = 1e-4;    ///< converged when the translation step is below this...
  double step_epsilon_rad = 1e-5;  ///< ...and the rotation step below this
  /// Degenerate input when the smallest eigenvalue of a cloud's covariance is below this
  /// fraction of the largest.
  double planar_eigenvalue_ratio = 1e-6;
  /// Degenerate result when the condition number of the Hessian's translation block exceeds
  /// this (see RegistrationResult::translation_condition).
  double max_translation_condition = 50.0;
  /// Throws std::invalid_argument naming the field when a value is out of range.
  void validate() const;
};

/// Points with their regularized covariances and a kd-tree over them.
class GicpCloud {
 public:
  GicpCloud(std::span<const Eigen::Vector3d> points, const GicpConfig& config);
  const std::vector<Eigen::Vector3d>& points() const { return tree_.points(); }
  const std::vector<Eigen::Matrix3d>& covariances() const { return covariances_; }
  const KdTree& tree() const { return tree_; }
  std::size_t size() const { return tree_.size(); }

 private:
  KdTree tree_;
  std::vector<Eigen::Matrix3d> covariances_;
};

RegistrationResult alignGicp(const GicpCloud& source, const GicpCloud& target,
                             const lie::SE3& guess_T_target_source, const GicpConfig& config);
RegistrationResult alignGicp(std::span<const Eigen::Vector3d> source,
                             std::span<const Eigen::Vector3d> target,
                             const lie::SE3& guess_T_target_source, const GicpConfig& config);

}  // namespace taiga::registration
