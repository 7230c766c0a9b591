// The lever arm estimator on synthetic motion with a known answer: an IMU derived analytically
// from a body that sways about all axes (or only yaws), and registered poses that place the body
// as if the lidar sat at a wrong lever arm, with millimetre noise.
#include "taiga/calib/lever_arm.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "taiga/core/errors.hpp"

namespace taiga::calib {
namespace {

using Eigen::Vector3d;

struct Motion {
  bool yaw_only = false;
  // theta(t) = amplitude .* sin(rate .* t): the attitude Exp(theta(t)).
  // Yaw only: a machine slewing back and forth (up to 80 deg/s).
  Vector3d amplitude() const { return yaw_only ? Vector3d(0, 0, 2.0) : Vector3d(0.3, 0.25, 0.8); }
  Vector3d rate() const { return {1.9, 1.3, yaw_only ? 0.7 : 0.4}; }
  lie::SO3 R(double t) const {
    return lie::SO3::Exp(amplitude().cwiseProduct((rate() * t).array().sin().matrix()));
  }
  Vector3d omega_body(double t) const {
    const Vector3d theta = amplitude().cwiseProduct((rate() * t).array().sin().matrix());
    const Vector3d theta_dot =
        amplitude().cwiseProduct(rate()).cwiseProduct((rate() * t).array().cos().matrix());
    return lie::SO3::rightJacobian(theta) * theta_dot;
  }
  Vector3d p(double t) const {
    return {1.2 * t + 0.3 * std::sin(0.9 * t), 0.5 * std::sin(0.5 * t), 0.05 * std::sin(2.1 * t)};
  }
  Vector3d a(double t) const {
    return {-0.3 * 0.81 * std::sin(0.9 * t), -0.5 * 0.25 * std::sin(0.5 * t),
            -0.05 * 4.41 * std::sin(2.1 * t)};
  }
};

/// `shift_m`: the lever arm moves by this halfway through (a mount that slipped), from
/// d_true - shift_m / 2 to d_true + shift_m / 2.
LeverArmInput simulate(const Motion& m, const Vector3d& d_true, const Vector3d& accel_bias,
                       unsigned seed, const Vector3d& shift_m = Vector3d::Zero()) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  auto noise3 = [&](double sigma) -> Vector3d {
    return Vector3d(normal(rng), normal(rng), normal(rng)) * sigma;
  };
  LeverArmInput in;
  for (double t = 0.0; t <= 31.0; t += 0.0025)
    in.imu_body.push_back(
        {.t_s = t,
         .acceleration_imu_mps2 =
             m.R(t).inverse() * (m.a(t) - in.gravity_odom_mps2) + accel_bias + noise3(0.004),
         .angular_velocity_imu_radps = m.omega_body(t) + noise3(0.0005)});
  in.chains.emplace_back();
  for (double t = 0.5; t < 30.0; t += 0.1) {
    if (std::fmod(t, 7.0) < 0.1) in.chains.emplace_back();  // a scan not registered now and then
    // The registration puts the body where the configured lever arm puts it: p_B + R d.
    const Vector3d d = d_true + (t < 15.0 ? -0.5 : 0.5) * shift_m;
    in.chains.back().push_back({t, lie::SE3(m.R(t), m.p(t) + m.R(t) * d + noise3(0.002))});
  }
  return in;
}

TEST(LeverArm, FindsTheLeverArmWhereTheRigTurnsAboutAllAxes) {
  const Vector3d d_true(0.02, -0.05, 0.03), accel_bias(0.03, -0.02, 0.05);
  for (unsigned seed : {1u, 2u}) {
    const LeverArmEstimate e = estimateLeverArm(simulate(Motion{}, d_true, accel_bias, seed));
    EXPECT_TRUE(e.observable.all());
    EXPECT_LT((e.correction_m - d_true).norm(), 0.005) << e.correction_m.transpose();
    EXPECT_LT((e.accel_bias_mps2 - accel_bias).norm(), 0.01);
    EXPECT_GT(e.sigma_m.minCoeff(), 0.0);
    EXPECT_LT(e.sigma_m.maxCoeff(), 0.01);
  }
}

TEST(LeverArm, TheJackknifeAgreesWithTheFormalSigmaOnConsistentData) {
  const LeverArmEstimate e =
      estimateLeverArm(simulate(Motion{}, Vector3d(0.02, -0.05, 0.03), Vector3d::Zero(), 5));
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(e.jackknife_sigma_m(i), 0.2 * e.formal_sigma_m(i)) << i;
    EXPECT_LT(e.jackknife_sigma_m(i), 3.0 * e.formal_sigma_m(i)) << i;
    EXPECT_EQ(e.sigma_m(i), std::max(e.formal_sigma_m(i), e.jackknife_sigma_m(i)));
  }
}

TEST(LeverArm, TheJackknifeSeesALeverArmThatChangedAlongTheWay) {
  // The stretches disagree along x only: the spread of the leave-one-block-out estimates says so.
  const Vector3d d_true(0.02, -0.05, 0.03);
  const LeverArmEstimate e =
      estimateLeverArm(simulate(Motion{}, d_true, Vector3d::Zero(), 3, Vector3d(0.02, 0.0, 0.0)));
  EXPECT_GT(e.jackknife_sigma_m.x(), 0.002);
  EXPECT_GT(e.jackknife_sigma_m.x(), 3.0 * e.jackknife_sigma_m.tail<2>().maxCoeff());
  EXPECT_LT((e.correction_m - d_true).norm(), 0.005);  // the mean of the two
}

TEST(LeverArm, YawOnlyHoldsTheVerticalComponent) {
  // Turning about z moves the lever arm's x and y, never its z: z is held and reported.
  const Vector3d d_true(0.02, -0.05, 0.03);
  const LeverArmEstimate e =
      estimateLeverArm(simulate(Motion{.yaw_only = true}, d_true, Vector3d::Zero(), 3));
  EXPECT_TRUE(e.observable(0));
  EXPECT_TRUE(e.observable(1));
  EXPECT_FALSE(e.observable(2));
  EXPECT_NEAR(e.correction_m.z(), 0.0, 1e-6);
  EXPECT_LT((e.correction_m.head<2>() - d_true.head<2>()).norm(), 0.008);
}

TEST(LeverArm, TooFewStepsIsAnError) {
  LeverArmInput in = simulate(Motion{}, Vector3d::Zero(), Vector3d::Zero(), 4);
  in.chains.resize(1);
  in.chains[0].resize(10);
  EXPECT_THROW(estimateLeverArm(in), InputError);
}

}  // namespace
}  // namespace taiga::calib
