// The analytic Jacobians of pf3's and pf6's residuals against central differences over the
// parameter update delta = [dt; dtheta] (residuals.hpp).
#include <gtest/gtest.h>

#include <functional>

#include "synthetic_fixes.hpp"
#include "taiga/georef/residuals.hpp"

namespace taiga::georef {
namespace {

using test::deg;

template <int Rows>
Eigen::Matrix<double, Rows, 6> numericalJacobian(
    const std::function<Eigen::Matrix<double, Rows, 1>(const lie::SE3&)>& residual,
    const lie::SE3& T) {
  constexpr double kStep = 1e-6;
  Eigen::Matrix<double, Rows, 6> J;
  for (int k = 0; k < 6; ++k) {
    Vector6d delta = Vector6d::Zero();
    delta[k] = kStep;
    J.col(k) = (residual(applyUpdate(T, delta)) - residual(applyUpdate(T, -delta))) / (2.0 * kStep);
  }
  return J;
}

const lie::SE3 kTEnuWorld(lie::SO3::fromRollPitchYaw(deg(1.5), deg(-2.0), deg(37.0)),
                          Eigen::Vector3d(312.5, -457.25, 23.1));

TEST(GeorefResiduals, ApplyUpdateMovesTranslationAndTurnsAboutEnuAxes) {
  Vector6d delta;
  delta << 1.0, 2.0, 3.0, 0.0, 0.0, deg(10.0);
  const lie::SE3 T = applyUpdate(kTEnuWorld, delta);
  EXPECT_LT((T.translation() - kTEnuWorld.translation() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  const lie::SO3 expected =
      lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), deg(10.0)) * kTEnuWorld.rotation();
  EXPECT_LT((T.rotation().inverse() * expected).angle(), 1e-12);
}

TEST(GeorefResiduals, PositionJacobianMatchesNumerical) {
  const Eigen::Vector3d p_world(12.0, -40.0, 3.5), p_enu(300.0, -420.0, 25.0);
  Matrix36d J;
  positionResidual(kTEnuWorld, p_world, p_enu, &J);
  const Matrix36d numerical = numericalJacobian<3>(
      [&](const lie::SE3& T) -> Eigen::Vector3d { return positionResidual(T, p_world, p_enu); },
      kTEnuWorld);
  EXPECT_LT((J - numerical).cwiseAbs().maxCoeff(), 1e-6) << J << "\n\n" << numerical;
}

TEST(GeorefResiduals, PoseJacobianMatchesNumericalAwayFromTheSolution) {
  // Measurement off by several degrees and metres, so Jr^-1(r) and Adj are not identities.
  const lie::SE3 T_world_body(lie::SO3::fromRollPitchYaw(deg(4.0), deg(-3.0), deg(120.0)),
                              Eigen::Vector3d(30.0, 12.0, 1.5));
  const lie::SE3 T_enu_meas =
      kTEnuWorld * T_world_body *
      lie::SE3::Exp((Vector6d() << 0.8, -1.2, 2.0, deg(3.0), deg(-2.0), deg(8.0)).finished());
  Matrix6d J;
  const Vector6d r = poseResidual(kTEnuWorld, T_world_body, T_enu_meas, &J);
  EXPECT_GT(r.norm(), 1.0);
  const Matrix6d numerical = numericalJacobian<6>(
      [&](const lie::SE3& T) -> Vector6d { return poseResidual(T, T_world_body, T_enu_meas); },
      kTEnuWorld);
  EXPECT_LT((J - numerical).cwiseAbs().maxCoeff(), 1e-5) << J << "\n\n" << numerical;
}

TEST(GeorefResiduals, PoseResidualVanishesAtTheTruth) {
  const lie::SE3 T_world_body(lie::SO3::fromRollPitchYaw(0.1, 0.2, 0.3), Eigen::Vector3d(1, 2, 3));
  EXPECT_LT(poseResidual(kTEnuWorld, T_world_body, kTEnuWorld * T_world_body).norm(), 1e-9);
}

}  // namespace
}  // namespace taiga::georef
