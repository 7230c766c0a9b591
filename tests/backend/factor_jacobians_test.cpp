// Every analytic factor Jacobian against central differences along the parameter blocks'
// tangents (PoseManifold for poses, plain vectors for motion blocks), at random states far from
// the measurements, so that no term hides behind a zero residual.
#include <gtest/gtest.h>

#include <array>
#include <numbers>
#include <random>
#include <vector>

#include "../imu/imu_test_motion.hpp"
#include "taiga/backend/gnss_factor.hpp"
#include "taiga/backend/imu_factor.hpp"
#include "taiga/backend/pose_factor.hpp"
#include "taiga/backend/position_factor.hpp"
#include "taiga/backend/relative_pose_factor.hpp"
#include "taiga/backend/state_prior.hpp"

namespace taiga::backend {
namespace {

using imu::test::kGravityWorld;
using imu::test::WavyMotion;

/// Largest difference between the analytic and the numerical tangent Jacobians of `factor`.
double worstJacobianError(const ceres::CostFunction& factor,
                          std::vector<std::vector<double>> blocks) {
  const int residuals = factor.num_residuals();
  const std::vector<int32_t>& sizes = factor.parameter_block_sizes();
  std::vector<const double*> parameters;
  for (auto& b : blocks) parameters.push_back(b.data());
  std::vector<std::vector<double>> jacobian_storage;
  std::vector<double*> jacobians;
  for (int32_t size : sizes) {
    jacobian_storage.emplace_back(residuals * size);
    jacobians.push_back(jacobian_storage.back().data());
  }
  std::vector<double> r0(residuals);
  EXPECT_TRUE(factor.Evaluate(parameters.data(), r0.data(), jacobians.data()));

  const PoseManifold pose_manifold;
  const double eps = 1e-6;
  double worst = 0.0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const bool is_pose = sizes[b] == kPoseSize;
    const int tangent = is_pose ? kPoseTangentSize : sizes[b];
    for (int k = 0; k < tangent; ++k) {
      std::vector<double> delta(tangent, 0.0);
      std::vector<double> r_plus(residuals), r_minus(residuals);
      for (double sign : {1.0, -1.0}) {
        delta[k] = sign * eps;
        std::vector<double> moved = blocks[b];
        if (is_pose) {
          pose_manifold.Plus(blocks[b].data(), delta.data(), moved.data());
        } else {
          moved[k] += delta[k];
        }
        std::vector<const double*> p = parameters;
        p[b] = moved.data();
        factor.Evaluate(p.data(), sign > 0 ? r_plus.data() : r_minus.data(), nullptr);
      }
      for (int i = 0; i < residuals; ++i) {
        const double numerical = (r_plus[i] - r_minus[i]) / (2 * eps);
        const double analytic =
            jacobian_storage[b][i * sizes[b] + k];  // row-major, tangent columns first
        worst =
            std::max(worst, std::abs(numerical - analytic) / std::max(1.0, std::abs(numerical)));
      }
    }
  }
  return worst;
}

StateBlocks randomState(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d theta(n(rng), n(rng), n(rng));
  imu::NavState s{
      lie::SO3::Exp(theta), {n(rng) * 5, n(rng) * 5, n(rng)}, {n(rng), n(rng), n(rng) * 0.2}};
  imu::ImuBias bias{{0.1 * n(rng), 0.1 * n(rng), 0.1 * n(rng)},
                    {0.01 * n(rng), 0.01 * n(rng), 0.01 * n(rng)}};
  return StateBlocks::from(s, bias);
}

std::vector<double> vec(const auto& array) { return {array.begin(), array.end()}; }

TEST(FactorJacobians, ImuFactorMatchesNumericalDifferentiation) {
  std::mt19937_64 rng(5);
  const imu::ImuBias bias_hat{{0.05, -0.02, 0.03}, {0.003, -0.002, 0.004}};
  imu::Preintegrator pre(bias_hat, imu::ImuNoise{});
  for (int k = 0; k < 50; ++k)
    pre.integrate(WavyMotion::accel(k * 0.005), WavyMotion::gyro(k * 0.005), 0.005);
  const ImuFactor factor(pre, kGravityWorld);
  std::normal_distribution<double> tilt_rad(0.0, 0.05);
  for (int trial = 0; trial < 5; ++trial) {
    const StateBlocks i = randomState(rng), j = randomState(rng);
    // The frame's tilt: zero (the odometry without the estimate) and a few degrees.
    const std::vector<double> tilt = trial == 0 ? std::vector<double>{0.0, 0.0}
                                                : std::vector<double>{tilt_rad(rng), tilt_rad(rng)};
    EXPECT_LT(
        worstJacobianError(factor, {vec(i.pose), vec(i.motion), vec(j.pose), vec(j.motion), tilt}),
        1e-5);
  }
}

TEST(FactorJacobians, PoseFactorMatchesNumericalDifferentiation) {
  std::mt19937_64 rng(6);
  lie::Matrix6 covariance = lie::Matrix6::Identity() * 0.01;
  covariance(0, 4) = covariance(4, 0) = 0.002;
  for (int trial = 0; trial < 5; ++trial) {
    const PoseFactor factor(randomState(rng).T_world_body(), covariance);
    EXPECT_LT(worstJacobianError(factor, {vec(randomState(rng).pose)}), 1e-6);
  }
}

TEST(FactorJacobians, RelativePoseFactorMatchesNumericalDifferentiation) {
  std::mt19937_64 rng(8);
  lie::Matrix6 covariance = lie::Matrix6::Identity() * 0.01;
  covariance(1, 3) = covariance(3, 1) = 0.003;
  for (int trial = 0; trial < 5; ++trial) {
    const lie::SE3 T_i_j_measured = randomState(rng).T_world_body();
    const RelativePoseFactor factor(T_i_j_measured, covariance);
    const StateBlocks i = randomState(rng), j = randomState(rng);
    EXPECT_LT(worstJacobianError(factor, {vec(i.pose), vec(j.pose)}), 1e-6);
    // Zero exactly at the measurement.
    const lie::SE3 T_world_j = i.T_world_body() * T_i_j_measured;
    EXPECT_LT(factor.error(i.T_world_body(), T_world_j).norm(), 1e-12);
  }
}

TEST(FactorJacobians, PositionFactorMatchesNumericalDifferentiation) {
  std::mt19937_64 rng(9);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity() * 0.5;
  covariance(0, 2) = covariance(2, 0) = 0.2;
  for (int trial = 0; trial < 5; ++trial) {
    const PositionFactor factor(randomState(rng).T_world_body().translation(), covariance);
    EXPECT_LT(worstJacobianError(factor, {vec(randomState(rng).pose)}), 1e-6);
  }
}

TEST(FactorJacobians, GnssFactorMatchesNumericalDifferentiation) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity() * 0.8;
  covariance(0, 1) = covariance(1, 0) = 0.3;
  covariance(2, 2) = 2.5;
  for (int trial = 0; trial < 5; ++trial) {
    // A lever arm, a fix far from the prediction and a yaw away from zero: every term counts.
    const Eigen::Vector3d d_body(n(rng), n(rng), 0.5 * n(rng));
    const GnssFactor factor(d_body, {20 * n(rng), 20 * n(rng), n(rng)}, covariance);
    const std::vector<double> enu{30 * n(rng), 30 * n(rng), 2 * n(rng), 2 * n(rng)};
    EXPECT_LT(worstJacobianError(factor, {vec(randomState(rng).pose), enu}), 1e-6);
  }
}

TEST(FactorJacobians, GnssFactorResidualIsTheWhitenedEnuDifference) {
  // 90 deg yaw: world x is north. A keyframe at (2, 0, 0) turned 90 deg, antenna 1 m ahead of
  // it (body x = world y): world (2, 1, 0), ENU (-1, 2, 0) + t (10, 20, 1) = (9, 22, 1).
  const lie::SE3 T_world_body(lie::SO3::fromRollPitchYaw(0, 0, std::numbers::pi / 2), {2, 0, 0});
  std::array<double, kPoseSize> pose{};
  writePoseBlock(T_world_body, pose.data());
  const std::array<double, kEnuWorldSize> enu{10, 20, 1, std::numbers::pi / 2};
  const GnssFactor factor({1, 0, 0}, {9, 22, 3}, Eigen::Vector3d(4, 4, 16).asDiagonal());
  const double* parameters[] = {pose.data(), enu.data()};
  Eigen::Vector3d r;
  ASSERT_TRUE(factor.Evaluate(parameters, r.data(), nullptr));
  EXPECT_NEAR(r.x(), 0.0, 1e-12);
  EXPECT_NEAR(r.y(), 0.0, 1e-12);
  EXPECT_NEAR(r.z(), -2.0 / 4.0, 1e-12);  // 2 m low, sigma 4 m
  // The block round trip keeps yaw and translation.
  const lie::SE3 T_enu_world = enuWorldFromBlock(enu.data());
  std::array<double, kEnuWorldSize> again{};
  writeEnuWorldBlock(T_enu_world, again.data());
  for (int i = 0; i < kEnuWorldSize; ++i) EXPECT_NEAR(again[i], enu[i], 1e-12);
}

TEST(FactorJacobians, StatePriorMatchesNumericalDifferentiation) {
  std::mt19937_64 rng(7);
  StatePrior::Covariance covariance = StatePrior::Covariance::Identity() * 0.04;
  covariance(2, 7) = covariance(7, 2) = 0.01;
  covariance(10, 16) = covariance(16, 10) = 0.005;  // accelerometer bias and the frame's tilt
  for (int trial = 0; trial < 5; ++trial) {
    const StatePrior factor(randomState(rng), {0.01, -0.02}, covariance);
    const StateBlocks x = randomState(rng);
    EXPECT_LT(worstJacobianError(factor, {vec(x.pose), vec(x.motion), {0.03, 0.01}}), 1e-6);
  }
}

TEST(FactorJacobians, ImuFactorIsZeroAtTheTrueStatesOfNoiselessReadings) {
  imu::Preintegrator pre({}, imu::ImuNoise{});
  const double dt = 1e-4;
  for (int k = 0; k < 1000; ++k)
    pre.integrate(WavyMotion::accel((k + 0.5) * dt), WavyMotion::gyro((k + 0.5) * dt), dt);
  const ImuFactor factor(pre, kGravityWorld);
  const Vector15 r = factor.rawResidual(StateBlocks::from(WavyMotion::state(0.0), {}),
                                        StateBlocks::from(WavyMotion::state(0.1), {}));
  EXPECT_LT(r.norm(), 1e-4);  // discretization error; a 1 cm/s velocity error alone gives 1e-2
}

}  // namespace
}  // namespace taiga::backend
