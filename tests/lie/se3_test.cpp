// SE(3)-specific checks: Exp against the 4x4 matrix exponential, the tangent ordering
// [rho; theta], the action on points with its Jacobians, and homogeneous-matrix round trips.
#include <gtest/gtest.h>

#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

#include "../support/lie_test_support.hpp"

namespace taiga::lie {
namespace {

// The Lie-algebra element of tau = [rho; theta]: [[theta]x rho; 0 0].
Matrix4 twistMatrix(const Vector6& tau) {
  Matrix4 m = Matrix4::Zero();
  m.topLeftCorner<3, 3>() = hat(tau.tail<3>());
  m.topRightCorner<3, 1>() = tau.head<3>();
  return m;
}

TEST(SE3, ExpMatchesMatrixExponential) {
  test::RandomLie rng(11);
  for (double angle : test::edgeCaseAngles()) {
    const Vector6 tau = makeTangent(rng.translation(), rng.unitVector() * angle);
    const Matrix4 expected = twistMatrix(tau).exp();
    EXPECT_TRUE(SE3::Exp(tau).matrix().isApprox(expected, 1e-12)) << tau.transpose();
  }
}

TEST(SE3, TangentOrderIsTranslationThenRotation) {
  const SE3 T = SE3::Exp(makeTangent(Vector3(1, 2, 3), Vector3::Zero()));
  EXPECT_TRUE(T.translation().isApprox(Vector3(1, 2, 3)));
  EXPECT_NEAR(T.rotation().angle(), 0.0, 1e-15);
  const SE3 R = SE3::Exp(makeTangent(Vector3::Zero(), Vector3(0, 0, 0.5)));
  EXPECT_TRUE(R.translation().isZero());
  EXPECT_NEAR(R.rotation().angle(), 0.5, 1e-15);
}

TEST(SE3, ActionComposesAsFramesDo) {
  // T_a_c = T_a_b * T_b_c maps p_c to p_a.
  test::RandomLie rng(12);
  const SE3 T_a_b = rng.se3(), T_b_c = rng.se3();
  const Vector3 p_c = rng.translation();
  EXPECT_TRUE(((T_a_b * T_b_c) * p_c).isApprox(T_a_b * (T_b_c * p_c), 1e-12));
  EXPECT_TRUE((T_a_b.inverse() * (T_a_b * p_c)).isApprox(p_c, 1e-12));
  EXPECT_TRUE((T_a_b * p_c).isApprox(T_a_b.rotation().matrix() * p_c + T_a_b.translation()));
}

TEST(SE3, ActionJacobiansMatchNumerical) {
  test::RandomLie rng(13);
  for (int i = 0; i < 20; ++i) {
    const SE3 T = rng.se3();
    const Vector3 p = rng.translation();
    Matrix36 J_T;
    Matrix3 J_p;
    T.act(p, &J_T, &J_p);
    EXPECT_TRUE(
        J_T.isApprox(test::numericalJacobian([&](const SE3& X) { return X * p; }, T), 1e-6));
    EXPECT_TRUE(
        J_p.isApprox(test::numericalJacobian([&](const Vector3& q) { return T * q; }, p), 1e-6));
  }
}

TEST(SE3, MatrixAndIsometryRoundTrip) {
  test::RandomLie rng(14);
  const SE3 T = rng.se3();
  EXPECT_TRUE(SE3::fromMatrix(T.matrix()).matrix().isApprox(T.matrix(), 1e-15));
  EXPECT_TRUE(SE3::fromIsometry(T.isometry()).matrix().isApprox(T.matrix(), 1e-15));
}

TEST(SE3, LogNearPiKeepsTranslation) {
  test::RandomLie rng(15);
  for (double angle : {std::numbers::pi, std::numbers::pi - 1e-8}) {
    const SE3 T(SO3::Exp(rng.unitVector() * angle), rng.translation());
    EXPECT_TRUE(SE3::Exp(T.Log()).matrix().isApprox(T.matrix(), 1e-10)) << angle;
  }
}

}  // namespace
}  // namespace taiga::lie
