#pragma once
// The square root of a factor's information, S with S^T S = Sigma^-1, for the whitened residual
// S r of every factor of the backend.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>

namespace taiga::backend {

/// The Cholesky factor of Sigma^-1 (transposed), as the factors always used. When that fails (a
/// covariance that spans more than double precision: a state that lost nearly all information,
/// a gap in the IMU readings), S = diag(l^-1/2) V^T from Sigma = V diag(l) V^T with l floored at
/// 1e-12 of the largest: a finite, slightly regularised factor instead of NaN.
template <int N>
Eigen::Matrix<double, N, N> sqrtInformation(const Eigen::Matrix<double, N, N>& covariance) {
  using Matrix = Eigen::Matrix<double, N, N>;
  const Eigen::LLT<Matrix> llt(covariance.inverse());
  if (llt.info() == Eigen::Success) {
    const Matrix S = llt.matrixL().transpose();
    if (S.allFinite()) return S;
  }
  const Eigen::SelfAdjointEigenSolver<Matrix> eigen(0.5 * (covariance + covariance.transpose()));
  const auto lambda =
      eigen.eigenvalues().cwiseMax(1e-12 * std::max(eigen.eigenvalues().maxCoeff(), 1e-300));
  return lambda.cwiseSqrt().cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace taiga::backend
