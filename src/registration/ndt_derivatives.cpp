// Score, gradient and Hessian of P2D- and D2D-NDT (see ndt.hpp for the model).
//
// With T(tau) = T * Exp(tau), a source point x moves to p(tau) = R x(tau) + t where
//   x(tau) = Exp(tau) x = x + rho + theta x x + 1/2 theta x rho + 1/2 theta x (theta x x) + O(3).
// Hence dp/dtau = R [I, -[x]x] and, for a vector w = R^T Sigma^-1 (p - mu), the contraction of the
// second derivatives (p - mu)^T Sigma^-1 d2p/dtau2 is the symmetric 6x6
//   [ 0            1/2 [w]x                          ]
//   [ -1/2 [w]x    1/2 (w x^T + x w^T) - (w . x) I   ].
// For one point and one cell with q = (p - mu)^T Sigma^-1 (p - mu), e = exp(-d2 q / 2), f = d1 e:
//   df/dtau    = -d1 d2 e g,                         g = J^T Sigma^-1 (p - mu)
//   d2f/dtau2  = -d1 d2 e (-d2 g g^T + J^T Sigma^-1 J + S(w))   (Magnusson Eq. 6.12-6.13).
#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "block_reduce.hpp"
#include "taiga/lie/so3.hpp"
#include "taiga/registration/ndt.hpp"

namespace taiga::registration {
namespace {

struct Partial {
  double score = 0.0;
  lie::Vector6 gradient = lie::Vector6::Zero();
  lie::Matrix6 hessian = lie::Matrix6::Zero();
  std::size_t num_inliers = 0;
};

// Adds the contribution of source point x (source frame) moved to p, scored against a cell with
// mean mu and inverse covariance B.
inline void accumulate(const Eigen::Vector3d& x, const Eigen::Matrix3d& R,
                       const Eigen::Matrix<double, 3, 6>& J, const Eigen::Vector3d& p,
                       const Eigen::Vector3d& mu, const Eigen::Matrix3d& B, const NdtConstants& k,
                       bool with_hessian, Partial& out) {
  const Eigen::Vector3d d = p - mu;
  const Eigen::Vector3d a = B * d;
  const double q = d.dot(a);
  // Beyond exponent 50 (about 15 sigma) a term is below 1e-21 of a full one: skipped (score and
  // derivatives alike), which saves the products for DIRECT7 neighbours far from the point.
  const double exponent = 0.5 * k.d2 * q;
  if (!(exponent < 50.0)) return;
  const double e = std::exp(-exponent);
  out.score += k.d1 * e;
  const lie::Vector6 g = J.transpose() * a;
  const double c = -k.d1 * k.d2 * e;  // > 0
  out.gradient += c * g;
  if (!with_hessian) return;
  const Eigen::Vector3d w = R.transpose() * a;
  lie::Matrix6 S = lie::Matrix6::Zero();
  const Eigen::Matrix3d w_hat = lie::hat(w);
  S.block<3, 3>(0, 3) = 0.5 * w_hat;
  S.block<3, 3>(3, 0) = -0.5 * w_hat;
  S.block<3, 3>(3, 3) =
      0.5 * (w * x.transpose() + x * w.transpose()) - w.dot(x) * Eigen::Matrix3d::Identity();
  const Eigen::Matrix<double, 3, 6> BJ = B * J;
  out.hessian += c * (-k.d2 * g * g.transpose() + J.transpose() * BJ + S);
}

inline Eigen::Matrix<double, 3, 6> pointJacobian(const Eigen::Matrix3d& R,
                                                 const Eigen::Vector3d& x) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>() = R;
  J.rightCols<3>() = -R * lie::hat(x);
  return J;
}

template <class Body>
NdtDerivatives reduce(std::size_t n, const Body& body) {
  const Partial total = detail::reduceInBlocks<Partial>(n, body, [](Partial& a, const Partial& b) {
    a.score += b.score;
    a.gradient += b.gradient;
    a.hessian += b.hessian;
    a.num_inliers += b.num_inliers;
  });
  NdtDerivatives out;
  out.score = total.score;
  out.gradient = total.gradient;
  out.hessian = total.hessian;
  out.num_inliers = total.num_inliers;
  return out;
}

Eigen::Matrix3d regularize(const Eigen::Matrix3d& covariance, double min_eigenvalue_ratio) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Vector3d lambda = solver.eigenvalues();
  lambda = lambda.cwiseMax(min_eigenvalue_ratio * std::max(lambda.maxCoeff(), 0.0));
  return solver.eigenvectors() * lambda.asDiagonal() * solver.eigenvectors().transpose();
}

}  // namespace

NdtDerivatives ndtDerivatives(std::span<const Eigen::Vector3d> source, const NdtTarget& target,
                              const lie::SE3& T_target_source, const NdtConfig& config,
                              bool with_hessian) {
  const NdtConstants k = ndtConstants(target.resolution_m(), config.outlier_ratio);
  const Eigen::Matrix3d R = T_target_source.rotation().matrix();
  const Eigen::Vector3d t = T_target_source.translation();
  return reduce(source.size(), [&](std::size_t i, Partial& out) {
    const Eigen::Vector3d& x = source[i];
    const Eigen::Vector3d p = R * x + t;
    const NdtCell* cells[7];
    const int n = target.neighbours(p, config.search, cells);
    if (n == 0) return;
    ++out.num_inliers;
    const Eigen::Matrix<double, 3, 6> J = pointJacobian(R, x);
    for (int c = 0; c < n; ++c) {
      accumulate(x, R, J, p, cells[c]->mean, cells[c]->inverse_covariance, k, with_hessian, out);
    }
  });
}

D2dSource makeD2dSource(std::span<const Eigen::Vector3d> source, const NdtConfig& config,
                        double resolution_m) {
  VoxelStatistics stats(resolution_m);
  stats.add(source);
  D2dSource out;
  for (const CellMoments& m : stats.moments(config.min_points_per_cell)) {
    const Eigen::Matrix3d C = regularize(m.covariance, config.min_eigenvalue_ratio);
    if (!(C.trace() > 0.0)) continue;
    out.means.push_back(m.mean);
    out.covariances.push_back(C);
  }
  return out;
}

NdtDerivatives d2dDerivatives(const D2dSource& source, const NdtTarget& target,
                              const lie::SE3& T_target_source, const NdtConfig& config,
                              bool with_hessian) {
  const NdtConstants k = ndtConstants(target.resolution_m(), config.outlier_ratio);
  const Eigen::Matrix3d R = T_target_source.rotation().matrix();
  const Eigen::Vector3d t = T_target_source.translation();
  return reduce(source.means.size(), [&](std::size_t i, Partial& out) {
    const Eigen::Vector3d& x = source.means[i];
    const Eigen::Vector3d p = R * x + t;
    const NdtCell* cells[7];
    const int n = target.neighbours(p, config.search, cells);
    if (n == 0) return;
    ++out.num_inliers;
    const Eigen::Matrix<double, 3, 6> J = pointJacobian(R, x);
    const Eigen::Matrix3d RCRt = R * source.covariances[i] * R.transpose();
    for (int c = 0; c < n; ++c) {
      const Eigen::Matrix3d B = (RCRt + cells[c]->covariance).inverse();
      accumulate(x, R, J, p, cells[c]->mean, B, k, with_hessian, out);
    }
  });
}

}  // namespace taiga::registration
