#include "taiga/registration/degeneracy.hpp"

#include <Eigen/Eigenvalues>
#include <limits>

#include "taiga/registration/result.hpp"

namespace taiga::registration {

double conditionNumber(const lie::Matrix6& H) {
  Eigen::SelfAdjointEigenSolver<lie::Matrix6> solver(H, Eigen::EigenvaluesOnly);
  const double lo = solver.eigenvalues()(0);
  const double hi = solver.eigenvalues()(5);
  if (!(lo > 0.0)) return std::numeric_limits<double>::infinity();
  return hi / lo;
}

double translationConditionNumber(const lie::Matrix6& H) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(H.topLeftCorner<3, 3>(),
                                                        Eigen::EigenvaluesOnly);
  const double lo = solver.eigenvalues()(0);
  if (!(lo > 0.0)) return std::numeric_limits<double>::infinity();
  return solver.eigenvalues()(2) / lo;
}

double planarityRatio(std::span<const Eigen::Vector3d> points) {
  if (points.size() < 3) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& p : points) C += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(C, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d& l = solver.eigenvalues();
  if (!(l(2) > 0.0)) return 0.0;
  return std::max(l(0), 0.0) / l(2);
}

std::optional<std::string> inputProblem(std::span<const Eigen::Vector3d> points,
                                        const std::string& what, std::size_t min_points,
                                        double planar_ratio) {
  if (points.empty()) return what + " cloud is empty";
  std::size_t non_finite = 0;
  for (const auto& p : points) non_finite += p.allFinite() ? 0 : 1;
  if (non_finite > 0) {
    return what + " cloud has " + std::to_string(non_finite) +
           " non-finite points (NaN or infinite coordinates); remove them first";
  }
  if (points.size() < min_points) {
    return what + " cloud has too few points (" + std::to_string(points.size()) + " < " +
           std::to_string(min_points) + ")";
  }
  const double ratio = planarityRatio(points);
  if (ratio < planar_ratio) {
    return what + " cloud is planar or linear (smallest/largest covariance eigenvalue " +
           std::to_string(ratio) + "): the registration is degenerate";
  }
  return std::nullopt;
}

}  // namespace taiga::registration
