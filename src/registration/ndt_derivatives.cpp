// Score, gradient and Hessian of P2D- and D2D-NDT (see ndt.hpp for the model).
//
// The terms are accumulated for a perturbation on the left, in the target frame, where a moved
// point needs no rotation: with p = T x and p(tau) = Exp(tau) p,
//   p(tau) = p + rho + theta x p + 1/2 theta x rho + 1/2 theta x (theta x p) + O(3),
// so dp/dtau = J = [I, -[p]x] and, for a = Sigma^-1 (p - mu), the contraction of the second
// derivatives a^T d2p/dtau2 is the symmetric 6x6
//   S = [ 0            1/2 [a]x                          ]
//       [ -1/2 [a]x    1/2 (a p^T + p a^T) - (a . p) I   ].
// For one point and one cell with q = (p - mu)^T Sigma^-1 (p - mu), e = exp(-d2 q / 2), f = d1 e:
//   df/dtau    = -d1 d2 e g,                         g = J^T a = [a; p x a]
//   d2f/dtau2  = -d1 d2 e (-d2 g g^T + J^T Sigma^-1 J + S)   (Magnusson Eq. 6.12-6.13).
// The optimizer perturbs on the right, T Exp(tau_r) = Exp(Adj(T) tau_r) T, so the sums are mapped
// once per evaluation: g_r = Adj^T g, H_r = Adj^T H Adj (exact: the map between tau_r and tau is
// linear). Per point this needs no 3x6 Jacobian products, and only the upper triangle of H is
// accumulated: about a third of the arithmetic of the right-perturbation form.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "block_reduce.hpp"
#include "taiga/registration/ndt.hpp"

namespace taiga::registration {
namespace {

struct Partial {
  double score = 0.0;
  lie::Vector6 gradient = lie::Vector6::Zero();
  lie::Matrix6 hessian = lie::Matrix6::Zero();  ///< upper triangle only until finished
  std::size_t num_inliers = 0;
};

// Adds the contribution of the moved point p (target frame) scored against a cell with mean mu
// and inverse covariance B, in the left-perturbation form above.
inline void accumulate(const Eigen::Vector3d& p, const Eigen::Vector3d& mu,
                       const Eigen::Matrix3d& B, const NdtConstants& k, bool with_hessian,
                       Partial& out) {
  const Eigen::Vector3d d = p - mu;
  const Eigen::Vector3d a = B * d;
  const double q = d.dot(a);
  // Beyond exponent 50 (about 15 sigma) a term is below 1e-21 of a full one: skipped (score and
  // derivatives alike), which saves the products for DIRECT7 neighbours far from the point.
  const double exponent = 0.5 * k.d2 * q;
  if (!(exponent < 50.0)) return;
  const double e = std::exp(-exponent);
  out.score += k.d1 * e;
  const double c = -k.d1 * k.d2 * e;  // > 0
  lie::Vector6 g;
  g << a, p.cross(a);
  out.gradient += c * g;
  if (!with_hessian) return;
  // BP = B [p]x column by column ([p]x e_j = p x e_j), then [p]x^T B [p]x row by row (row i of
  // [p]x^T is (p x e_i)^T).
  Eigen::Matrix3d BP;
  BP.col(0) = p.z() * B.col(1) - p.y() * B.col(2);
  BP.col(1) = p.x() * B.col(2) - p.z() * B.col(0);
  BP.col(2) = p.y() * B.col(0) - p.x() * B.col(1);
  Eigen::Matrix3d PtBP;
  PtBP.row(0) = p.z() * BP.row(1) - p.y() * BP.row(2);
  PtBP.row(1) = p.x() * BP.row(2) - p.z() * BP.row(0);
  PtBP.row(2) = p.y() * BP.row(0) - p.x() * BP.row(1);
  const double cg = -c * k.d2;
  const double a_dot_p = a.dot(p);
  // [a]x entries for the off-diagonal block of S.
  const double a_hat[3][3] = {{0.0, -a.z(), a.y()}, {a.z(), 0.0, -a.x()}, {-a.y(), a.x(), 0.0}};
  lie::Matrix6& H = out.hessian;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i <= j; ++i) H(i, j) += c * B(i, j) + cg * g[i] * g[j];
    for (int i = 0; i < 3; ++i) {
      H(i, j + 3) += c * (-BP(i, j) + 0.5 * a_hat[i][j]) + cg * g[i] * g[j + 3];
    }
    for (int i = 0; i <= j; ++i) {
      const double s = 0.5 * (a[i] * p[j] + p[i] * a[j]) - (i == j ? a_dot_p : 0.0);
      H(i + 3, j + 3) += c * (PtBP(i, j) + s) + cg * g[i + 3] * g[j + 3];
    }
  }
}

// A stem cell's term (ndt.hpp, "Stem cells"): the Gaussian at the circle's point nearest p, with
// the radial and vertical inverse variances. Its gradient is exact (d|p - c|/dp = n); the
// Hessian leaves out the circle's curvature, as point-to-plane ICP leaves out a surface's.
inline void accumulateStem(const Eigen::Vector3d& p, const NdtCell& cell, const NdtConstants& k,
                           bool with_hessian, Partial& out) {
  const Eigen::Vector2d d = p.head<2>() - cell.stem_centre;
  const double rho = d.norm();
  if (!(rho > 1e-6)) return;
  const Eigen::Vector3d n(d.x() / rho, d.y() / rho, 0.0);
  const Eigen::Vector3d mu(cell.stem_centre.x() + cell.stem_radius_m * n.x(),
                           cell.stem_centre.y() + cell.stem_radius_m * n.y(), cell.mean.z());
  Eigen::Matrix3d B = cell.inverse_radial_variance * n * n.transpose();
  B(2, 2) = cell.inverse_vertical_variance;
  accumulate(p, mu, B, k, with_hessian, out);
}

inline void accumulateCell(const Eigen::Vector3d& p, const NdtCell& cell, const NdtConstants& k,
                           bool with_hessian, Partial& out) {
  if (cell.stem) accumulateStem(p, cell, k, with_hessian, out);
  else accumulate(p, cell.mean, cell.inverse_covariance, k, with_hessian, out);
}

template <class Body>
NdtDerivatives reduce(std::size_t n, const lie::SE3& T_target_source, const Body& body) {
  const Partial total = detail::reduceInBlocks<Partial>(n, body, [](Partial& a, const Partial& b) {
    a.score += b.score;
    a.gradient += b.gradient;
    a.hessian += b.hessian;
    a.num_inliers += b.num_inliers;
  });
  const lie::Matrix6 adjoint = T_target_source.adjoint();
  const lie::Matrix6 hessian_left = total.hessian.selfadjointView<Eigen::Upper>();
  NdtDerivatives out;
  out.score = total.score;
  out.gradient = adjoint.transpose() * total.gradient;
  out.hessian = adjoint.transpose() * hessian_left * adjoint;
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
                              bool with_hessian, NeighbourCache* cache) {
  const NdtConstants k = ndtConstants(target.resolution_m(), config.outlier_ratio);
  const Eigen::Matrix3d R = T_target_source.rotation().matrix();
  const Eigen::Vector3d t = T_target_source.translation();
  return reduce(source.size(), T_target_source, [&](std::size_t i, Partial& out) {
    const Eigen::Vector3d p = R * source[i] + t;
    const NdtCell* found[7];
    const NdtCell* const* cells = found;
    int n = 0;
    if (cache) {  // each point's entry is written by the one thread that scores the point
      NeighbourCache::Entry& entry = cache->entries[i];
      const VoxelKey key = target.voxelOf(p);
      if (key != entry.key) {
        entry.key = key;
        entry.count = target.neighboursOf(key, config.search, entry.cells);
      }
      n = entry.count;
      cells = entry.cells;
    } else {
      n = target.neighbours(p, config.search, found);
    }
    if (n == 0) return;
    ++out.num_inliers;
    for (int c = 0; c < n; ++c) {
      accumulateCell(p, *cells[c], k, with_hessian, out);
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
  return reduce(source.means.size(), T_target_source, [&](std::size_t i, Partial& out) {
    const Eigen::Vector3d p = R * source.means[i] + t;
    const NdtCell* cells[7];
    const int n = target.neighbours(p, config.search, cells);
    if (n == 0) return;
    ++out.num_inliers;
    const Eigen::Matrix3d RCRt = R * source.covariances[i] * R.transpose();
    for (int c = 0; c < n; ++c) {
      const Eigen::Matrix3d B = (RCRt + cells[c]->covariance).inverse();
      accumulate(p, cells[c]->mean, B, k, with_hessian, out);
    }
  });
}

}  // namespace taiga::registration
