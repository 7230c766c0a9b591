#include "taiga/imu/preintegration.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "imu_test_motion.hpp"

namespace taiga::imu {
namespace {

using test::kGravityWorld;
using test::WavyMotion;

/// Preintegrates WavyMotion's exact readings over [t0, t0 + duration] in n steps, each reading
/// taken at the middle of its step (midpoint rule, second-order accurate).
Preintegrator preintegrateWavy(double t0, double duration, int n, const ImuBias& bias_hat = {},
                               const ImuBias& true_bias = {}) {
  Preintegrator pre(bias_hat, ImuNoise{});
  const double dt = duration / n;
  for (int k = 0; k < n; ++k) {
    const double t = t0 + (k + 0.5) * dt;
    pre.integrate(WavyMotion::accel(t) + true_bias.accel_mps2,
                  WavyMotion::gyro(t) + true_bias.gyro_radps, dt);
  }
  return pre;
}

/// Largest of the rotation (rad), velocity (m/s) and position (m) errors of a prediction.
double predictionError(const NavState& predicted, const NavState& truth) {
  return std::max({(predicted.R_world_body.inverse() * truth.R_world_body).angle(),
                   (predicted.v_world - truth.v_world).norm(),
                   (predicted.p_world - truth.p_world).norm()});
}

TEST(Preintegration, PredictsTheTrueMotionFromExactReadings) {
  const double t0 = 0.7, duration = 1.0;
  const NavState truth = WavyMotion::state(t0 + duration);
  const Preintegrator fine = preintegrateWavy(t0, duration, 10000);
  const Preintegrator coarse = preintegrateWavy(t0, duration, 2500);
  const double fine_error =
      predictionError(fine.predict(WavyMotion::state(t0), {}, kGravityWorld), truth);
  const double coarse_error =
      predictionError(coarse.predict(WavyMotion::state(t0), {}, kGravityWorld), truth);
  // The scheme holds the rotation of a step's start over the step (first order in dt): the error
  // is small and shrinks with the step, as a consistent integrator's must.
  EXPECT_LT(fine_error, 2e-4);
  EXPECT_LT(fine_error, 0.35 * coarse_error);
  EXPECT_NEAR(fine.deltaTime(), duration, 1e-12);
  EXPECT_LT(fine.residual(WavyMotion::state(t0), truth, {}, kGravityWorld).norm(), 2e-4);
  const NavState predicted = fine.predict(WavyMotion::state(t0), {}, kGravityWorld);
  EXPECT_LT(fine.residual(WavyMotion::state(t0), predicted, {}, kGravityWorld).norm(), 1e-12);
}

TEST(Preintegration, EqualsDirectIntegrationInTheWorldFrame) {
  // The preintegrated increments reorder the sums of direct Euler integration in the world frame;
  // both must give the same state for the same readings, whatever the readings.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  const ImuBias bias{{0.05, -0.1, 0.2}, {0.01, 0.02, -0.015}};
  Preintegrator pre(bias, ImuNoise{});
  NavState direct = WavyMotion::state(0.0);
  const NavState start = direct;
  const double dt = 0.005;
  for (int k = 0; k < 300; ++k) {
    const Vector3 accel = WavyMotion::accel(k * dt) + Vector3(noise(rng), noise(rng), noise(rng));
    const Vector3 gyro =
        WavyMotion::gyro(k * dt) + 0.3 * Vector3(noise(rng), noise(rng), noise(rng));
    pre.integrate(accel, gyro, dt);
    const Vector3 accel_world = direct.R_world_body * (accel - bias.accel_mps2);
    direct.p_world += direct.v_world * dt + 0.5 * (kGravityWorld + accel_world) * dt * dt;
    direct.v_world += (kGravityWorld + accel_world) * dt;
    direct.R_world_body = direct.R_world_body * lie::SO3::Exp((gyro - bias.gyro_radps) * dt);
  }
  const NavState predicted = pre.predict(start, bias, kGravityWorld);
  EXPECT_LT((predicted.R_world_body.inverse() * direct.R_world_body).angle(), 1e-12);
  EXPECT_LT((predicted.v_world - direct.v_world).norm(), 1e-11);
  EXPECT_LT((predicted.p_world - direct.p_world).norm(), 1e-11);
}

TEST(Preintegration, BiasJacobiansMatchNumericalDifferentiation) {
  const ImuBias bias_hat{{0.1, -0.05, 0.08}, {0.02, -0.01, 0.03}};
  const Preintegrator pre = preintegrateWavy(0.3, 0.5, 100, bias_hat);
  const double eps = 1e-6;
  for (int axis = 0; axis < 6; ++axis) {
    ImuBias perturbed = bias_hat;
    (axis < 3 ? perturbed.accel_mps2 : perturbed.gyro_radps)[axis % 3] += eps;
    const Preintegrator moved = preintegrateWavy(0.3, 0.5, 100, perturbed);
    const Vector3 dR_num = (pre.deltaR().inverse() * moved.deltaR()).Log() / eps;
    const Vector3 dV_num = (moved.deltaV() - pre.deltaV()) / eps;
    const Vector3 dP_num = (moved.deltaP() - pre.deltaP()) / eps;
    const Vector3 dR_ana = axis < 3 ? Vector3::Zero() : Vector3(pre.dR_dbg().col(axis % 3));
    const Vector3 dV_ana = axis < 3 ? pre.dV_dba().col(axis) : pre.dV_dbg().col(axis % 3);
    const Vector3 dP_ana = axis < 3 ? pre.dP_dba().col(axis) : pre.dP_dbg().col(axis % 3);
    EXPECT_LT((dR_num - dR_ana).norm(), 1e-5) << "axis " << axis;
    EXPECT_LT((dV_num - dV_ana).norm(), 1e-4) << "axis " << axis;
    EXPECT_LT((dP_num - dP_ana).norm(), 1e-4) << "axis " << axis;
  }
  // Jacobians that the motion makes non-trivial: a wrong sign or a missing term shows here.
  EXPECT_GT(pre.dV_dbg().norm(), 0.01);
  EXPECT_GT(pre.dP_dbg().norm(), 0.001);
}

/// Largest error of the first-order bias correction from bias 0 to `bias` against reintegrating.
double biasCorrectionRemainder(const ImuBias& bias) {
  const Preintegrator at_zero = preintegrateWavy(0.0, 0.5, 200, {}, bias);
  const Preintegrator at_truth = preintegrateWavy(0.0, 0.5, 200, bias, bias);
  return std::max({(at_zero.correctedDeltaR(bias).inverse() * at_truth.deltaR()).angle(),
                   (at_zero.correctedDeltaV(bias) - at_truth.deltaV()).norm(),
                   (at_zero.correctedDeltaP(bias) - at_truth.deltaP()).norm()});
}

TEST(Preintegration, FirstOrderBiasCorrectionLeavesASecondOrderRemainder) {
  const ImuBias bias{{0.05, -0.04, 0.03}, {0.004, -0.003, 0.005}};
  const ImuBias half_bias{bias.accel_mps2 / 2, bias.gyro_radps / 2};
  const double remainder = biasCorrectionRemainder(bias);
  EXPECT_LT(remainder, 1e-4);
  // Quadratic in the bias change: halving it quarters the remainder.
  EXPECT_NEAR(remainder / biasCorrectionRemainder(half_bias), 4.0, 0.5);
  // ... while the bias itself moved the increments by far more.
  const Preintegrator at_zero = preintegrateWavy(0.0, 0.5, 200, {}, bias);
  EXPECT_GT((at_zero.deltaV() - preintegrateWavy(0.0, 0.5, 200).deltaV()).norm(), 1e-2);
}

TEST(Preintegration, CovarianceMatchesMonteCarloSpread) {
  const ImuNoise noise{.accel_noise_density = 0.02, .gyro_noise_density = 0.005};
  const double rate_hz = 200.0, dt = 1.0 / rate_hz;
  const int steps = 200, runs = 3000;
  std::vector<Vector3> accel(steps), gyro(steps);
  for (int k = 0; k < steps; ++k) {
    accel[k] = WavyMotion::accel((k + 0.5) * dt);
    gyro[k] = WavyMotion::gyro((k + 0.5) * dt);
  }
  Preintegrator clean({}, noise);
  for (int k = 0; k < steps; ++k) clean.integrate(accel[k], gyro[k], dt);

  std::mt19937_64 rng(42);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double accel_sigma = noise.accel_noise_density / std::sqrt(dt);
  const double gyro_sigma = noise.gyro_noise_density / std::sqrt(dt);
  Matrix9 empirical = Matrix9::Zero();
  for (int run = 0; run < runs; ++run) {
    Preintegrator noisy({}, noise);
    for (int k = 0; k < steps; ++k) {
      noisy.integrate(accel[k] + accel_sigma * Vector3(unit(rng), unit(rng), unit(rng)),
                      gyro[k] + gyro_sigma * Vector3(unit(rng), unit(rng), unit(rng)), dt);
    }
    Vector9 error;
    error << (clean.deltaR().inverse() * noisy.deltaR()).Log(), noisy.deltaV() - clean.deltaV(),
        noisy.deltaP() - clean.deltaP();
    empirical += error * error.transpose() / runs;
  }
  const Matrix9& propagated = clean.covariance();
  for (int i = 0; i < 9; ++i) {
    EXPECT_NEAR(empirical(i, i) / propagated(i, i), 1.0, 0.1) << "diagonal " << i;
  }
  // Correlations between the blocks (rotation error drives velocity and position error).
  EXPECT_LT((empirical - propagated).norm() / propagated.norm(), 0.1);
}

TEST(Preintegration, RejectsANonPositiveStep) {
  Preintegrator pre({}, ImuNoise{});
  EXPECT_THROW(pre.integrate(Vector3::Zero(), Vector3::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(pre.integrate(Vector3::Zero(), Vector3::Zero(), -1e-3), std::invalid_argument);
}

}  // namespace
}  // namespace taiga::imu
