// SO(3)-specific checks: hat/vee, agreement with Eigen's angle-axis and the matrix exponential,
// roll/pitch/yaw, and rotations at and around pi where Log has to pick a hemisphere.
#include <gtest/gtest.h>

#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

#include "../support/lie_test_support.hpp"

namespace taiga::lie {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(SO3, HatIsTheCrossProductAndVeeItsInverse) {
  const Vector3 v(0.3, -1.2, 2.0), w(-0.7, 0.1, 0.4);
  EXPECT_TRUE((hat(v) * w).isApprox(v.cross(w)));
  EXPECT_TRUE(vee(hat(v)).isApprox(v));
  EXPECT_TRUE((hat(v) + hat(v).transpose()).isZero());
}

TEST(SO3, ExpMatchesAngleAxisAndMatrixExponential) {
  test::RandomLie rng(1);
  for (double angle : test::edgeCaseAngles()) {
    const Vector3 axis = rng.unitVector();
    const Matrix3 expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_TRUE(SO3::Exp(axis * angle).matrix().isApprox(expected, 1e-14)) << angle;
    const Matrix3 expm = hat(axis * angle).exp();
    EXPECT_TRUE(SO3::Exp(axis * angle).matrix().isApprox(expm, 1e-12)) << angle;
  }
}

TEST(SO3, LogReturnsAnglesInZeroToPi) {
  test::RandomLie rng(2);
  for (int i = 0; i < 200; ++i) {
    // Quaternions with either sign of w must give the same rotation vector.
    const Eigen::Vector4d c = Eigen::Vector4d::Random();
    const Eigen::Quaterniond q(c[0], c[1], c[2], c[3]);
    const Eigen::Quaterniond minus_q(-c[0], -c[1], -c[2], -c[3]);
    const Vector3 theta = SO3(q).Log();
    EXPECT_LE(theta.norm(), kPi + 1e-12);
    EXPECT_TRUE(theta.isApprox(SO3(minus_q).Log(), 1e-12));
  }
}

TEST(SO3, RotationsAtAndNearPi) {
  test::RandomLie rng(3);
  for (double angle : {kPi, kPi - 1e-9, kPi - 1e-6, kPi + 1e-6}) {
    const Vector3 axis = rng.unitVector();
    const SO3 R = SO3::Exp(axis * angle);
    const Vector3 theta = R.Log();
    // Exp(Log(R)) = R, |Log(R)| <= pi, and the axis is +-axis.
    EXPECT_TRUE(SO3::Exp(theta).matrix().isApprox(R.matrix(), 1e-12)) << angle;
    EXPECT_NEAR(theta.norm(), angle > kPi ? 2.0 * kPi - angle : angle, 1e-9);
    EXPECT_NEAR(std::abs(theta.normalized().dot(axis)), 1.0, 1e-9);
    // From the rotation matrix as well, where the quaternion conversion takes another branch.
    EXPECT_TRUE(SO3::Exp(SO3::fromMatrix(R.matrix()).Log()).matrix().isApprox(R.matrix(), 1e-12));
    // The inverse Jacobian stays finite at pi.
    EXPECT_TRUE(SO3::rightJacobianInverse(theta).allFinite());
  }
}

TEST(SO3, ActionAndItsJacobians) {
  test::RandomLie rng(4);
  for (int i = 0; i < 20; ++i) {
    const SO3 R = rng.so3();
    const Vector3 p = rng.translation();
    Matrix3 J_R, J_p;
    EXPECT_TRUE(R.act(p, &J_R, &J_p).isApprox(R.matrix() * p));
    EXPECT_TRUE(
        J_R.isApprox(test::numericalJacobian([&](const SO3& X) { return X * p; }, R), 1e-6));
    EXPECT_TRUE(
        J_p.isApprox(test::numericalJacobian([&](const Vector3& q) { return R * q; }, p), 1e-6));
  }
}

TEST(SO3, RollPitchYawIsExtrinsicXYZ) {
  const double roll = 0.1, pitch = -0.4, yaw = 2.0;
  const Matrix3 expected =
      (Eigen::AngleAxisd(yaw, Vector3::UnitZ()) * Eigen::AngleAxisd(pitch, Vector3::UnitY()) *
       Eigen::AngleAxisd(roll, Vector3::UnitX()))
          .toRotationMatrix();
  EXPECT_TRUE(SO3::fromRollPitchYaw(roll, pitch, yaw).matrix().isApprox(expected, 1e-14));
  // Yaw of 90 degrees turns the x axis into the y axis.
  EXPECT_TRUE((SO3::fromRollPitchYaw(0, 0, kPi / 2) * Vector3::UnitX()).isApprox(Vector3::UnitY()));
}

TEST(SO3, YawIsTheHeadingOfRollPitchYaw) {
  EXPECT_NEAR(SO3::fromRollPitchYaw(0.1, -0.4, 2.0).yaw(), 2.0, 1e-12);
  EXPECT_NEAR(SO3::fromRollPitchYaw(-0.3, 0.2, -2.5).yaw(), -2.5, 1e-12);
  EXPECT_NEAR(SO3::fromRollPitchYaw(0.0, 0.0, 0.0).yaw(), 0.0, 1e-15);
}

TEST(SO3, FromMatrixProjectsANoisyMatrix) {
  const SO3 R = SO3::fromAxisAngle(Vector3(1, 2, 3), 0.7);
  const Matrix3 noisy = R.matrix() + 1e-7 * Matrix3::Ones();
  const SO3 projected = SO3::fromMatrix(noisy);
  EXPECT_TRUE(
      (projected.matrix() * projected.matrix().transpose()).isApprox(Matrix3::Identity(), 1e-14));
  EXPECT_LT(projected.minus(R).norm(), 1e-6);
}

}  // namespace
}  // namespace taiga::lie
