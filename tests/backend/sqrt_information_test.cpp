// The square root of a factor's information: the Cholesky factor for an ordinary covariance,
// and a finite one when the covariance spans more than double precision (where the Cholesky
// factor of its inverse is NaN and made the odometry crash on a gap in the IMU readings).
#include "taiga/backend/sqrt_information.hpp"

#include <gtest/gtest.h>

namespace taiga::backend {
namespace {

TEST(SqrtInformation, IsTheCholeskyFactorForAnOrdinaryCovariance) {
  Eigen::Matrix3d covariance;
  covariance << 4e-4, 1e-4, 0.0, 1e-4, 9e-4, -2e-4, 0.0, -2e-4, 1e-2;
  const Eigen::Matrix3d S = sqrtInformation<3>(covariance);
  EXPECT_LT((S.transpose() * S - covariance.inverse()).norm(), 1e-9 * covariance.inverse().norm());
  EXPECT_EQ(S(1, 0), 0.0);  // upper triangular: L^T
  EXPECT_EQ(S(2, 0), 0.0);
}

TEST(SqrtInformation, IsFiniteWhenTheCovarianceSpansMoreThanDoublePrecision) {
  // A state that lost nearly all its information in one direction: variances from 1e-14 to 1e6
  // in a rotated basis, so that the inverse is not positive definite in double precision.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const Eigen::Matrix3d covariance =
      R * Eigen::Vector3d(1e-14, 1e-4, 1e6).asDiagonal() * R.transpose();
  // The premise: Cholesky fails here.
  const Eigen::LLT<Eigen::Matrix3d> llt(covariance.inverse());
  EXPECT_TRUE(llt.info() != Eigen::Success || !llt.matrixL().toDenseMatrix().allFinite());
  const Eigen::Matrix3d S = sqrtInformation<3>(covariance);
  ASSERT_TRUE(S.allFinite());
  // Whitened, the well-determined directions keep their weight (1/sqrt of the variance, up to the
  // floor at 1e-12 of the largest variance).
  const Eigen::Vector3d well = R.col(1);
  EXPECT_NEAR((S * well).norm(), 1.0 / std::sqrt(1e-4), 1e-3 / std::sqrt(1e-4));
  EXPECT_GT((S * R.col(0)).norm(), (S * well).norm());
}

}  // namespace
}  // namespace taiga::backend
