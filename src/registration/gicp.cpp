#include "taiga/registration/gicp.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <stdexcept>
#include <string>

#include "block_reduce.hpp"
#include "taiga/lie/so3.hpp"
#include "taiga/registration/degeneracy.hpp"

namespace taiga::registration {
namespace {

constexpr std::size_t kMinPoints = 10;

struct Partial {
  lie::Matrix6 H = lie::Matrix6::Zero();
  lie::Vector6 b = lie::Vector6::Zero();
  double error = 0.0;
  std::size_t num_inliers = 0;
};

Partial linearize(const GicpCloud& source, const GicpCloud& target, const lie::SE3& T,
                  double max_sq) {
  const Eigen::Matrix3d R = T.rotation().matrix();
  const Eigen::Vector3d t = T.translation();
  const auto& xs = source.points();
  return detail::reduceInBlocks<Partial>(
      xs.size(),
      [&](std::size_t i, Partial& out) {
        const Eigen::Vector3d p = R * xs[i] + t;
        std::size_t j;
        double sq;
        if (!target.tree().nearest(p, j, sq) || sq > max_sq) return;
        ++out.num_inliers;
        const Eigen::Matrix3d C =
            target.covariances()[j] + R * source.covariances()[i] * R.transpose();
        const Eigen::Matrix3d M = C.inverse();
        const Eigen::Vector3d r = p - target.points()[j];
        Eigen::Matrix<double, 3, 6> J;
        J.leftCols<3>() = R;
        J.rightCols<3>() = -R * lie::hat(xs[i]);
        const Eigen::Matrix<double, 3, 6> MJ = M * J;
        out.H += J.transpose() * MJ;
        out.b += MJ.transpose() * r;
        out.error += r.dot(M * r);
      },
      [](Partial& a, const Partial& b) {
        a.H += b.H;
        a.b += b.b;
        a.error += b.error;
        a.num_inliers += b.num_inliers;
      });
}

}  // namespace

void GicpConfig::validate() const {
  auto fail = [](const std::string& field, const std::string& expected, double value) {
    throw std::invalid_argument("GicpConfig." + field + ": expected " + expected + ", got " +
                                std::to_string(value));
  };
  if (num_neighbours < 5) fail("num_neighbours", ">= 5", static_cast<double>(num_neighbours));
  if (!(covariance_epsilon > 0.0 && covariance_epsilon <= 1.0)) {
    fail("covariance_epsilon", "(0, 1] m^2", covariance_epsilon);
  }
  if (!(max_correspondence_distance_m > 0.0)) {
    fail("max_correspondence_distance_m", "> 0 m", max_correspondence_distance_m);
  }
  if (max_iterations < 1) fail("max_iterations", ">= 1", max_iterations);
  if (!(max_translation_condition >= 1.0)) {
    fail("max_translation_condition", ">= 1", max_translation_condition);
  }
  if (!(step_epsilon_m > 0.0)) fail("step_epsilon_m", "> 0 m", step_epsilon_m);
  if (!(step_epsilon_rad > 0.0)) fail("step_epsilon_rad", "> 0 rad", step_epsilon_rad);
}

GicpCloud::GicpCloud(std::span<const Eigen::Vector3d> points, const GicpConfig& config)
    : tree_(points), covariances_(points.size(), Eigen::Matrix3d::Identity()) {
  const std::size_t k = std::min(config.num_neighbours, points.size());
  if (k < 3) return;
  const auto& xs = tree_.points();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, xs.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<std::size_t> indices(k);
                      std::vector<double> sq(k);
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const std::size_t n = tree_.knn(xs[i], k, indices.data(), sq.data());
                        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
                        for (std::size_t m = 0; m < n; ++m) mean += xs[indices[m]];
                        mean /= static_cast<double>(n);
                        Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
                        for (std::size_t m = 0; m < n; ++m) {
                          const Eigen::Vector3d d = xs[indices[m]] - mean;
                          C += d * d.transpose();
                        }
                        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(C);
                        const Eigen::Matrix3d& V = solver.eigenvectors();
                        const Eigen::Vector3d lambda(config.covariance_epsilon, 1.0, 1.0);
                        covariances_[i] = V * lambda.asDiagonal() * V.transpose();
                      }
                    });
}

RegistrationResult alignGicp(const GicpCloud& source, const GicpCloud& target,
                             const lie::SE3& guess, const GicpConfig& config) {
  config.validate();
  RegistrationResult result;
  result.T_target_source = guess;
  for (const auto& [cloud, name] : {std::pair{&source, "source"}, std::pair{&target, "target"}}) {
    if (auto problem =
            inputProblem(cloud->points(), name, kMinPoints, config.planar_eigenvalue_ratio)) {
      result.reason = *problem;
      return result;
    }
  }
  const double max_sq = config.max_correspondence_distance_m * config.max_correspondence_distance_m;
  lie::SE3 T = guess;
  bool small_step = false;
  Partial lin;
  for (int it = 1; it <= config.max_iterations; ++it) {
    lin = linearize(source, target, T, max_sq);
    result.iterations = it;
    if (lin.num_inliers < 6) break;
    const lie::Vector6 step = lin.H.ldlt().solve(-lin.b);
    if (!step.allFinite()) break;
    T = T.plus(step);
    if (step.head<3>().norm() < config.step_epsilon_m &&
        step.tail<3>().norm() < config.step_epsilon_rad) {
      small_step = true;
      break;
    }
  }
  result.T_target_source = T;
  result.num_inliers = lin.num_inliers;
  result.hessian = lin.H;
  result.hessian_condition = conditionNumber(lin.H);
  result.translation_condition = translationConditionNumber(lin.H);
  result.cost = lin.error;
  if (lin.num_inliers < 6) {
    result.reason = "too few correspondences within max_correspondence_distance_m (" +
                    std::to_string(lin.num_inliers) + ")";
  } else if (!std::isfinite(result.hessian_condition)) {
    result.reason = "Hessian not positive definite (degenerate geometry)";
  } else if (result.translation_condition > config.max_translation_condition) {
    result.reason = "degenerate: a translation is poorly constrained (condition number " +
                    std::to_string(result.translation_condition) +
                    " of the Hessian's translation block)";
  } else if (!small_step) {
    result.reason =
        "no convergence within max_iterations (" + std::to_string(config.max_iterations) + ")";
  } else {
    result.converged = true;
  }
  return result;
}

RegistrationResult alignGicp(std::span<const Eigen::Vector3d> source,
                             std::span<const Eigen::Vector3d> target, const lie::SE3& guess,
                             const GicpConfig& config) {
  config.validate();
  return alignGicp(GicpCloud(source, config), GicpCloud(target, config), guess, config);
}

}  // namespace taiga::registration
