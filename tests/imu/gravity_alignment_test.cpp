#include "taiga/imu/gravity_alignment.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "imu_test_motion.hpp"
#include "taiga/core/angles.hpp"

namespace taiga::imu {
namespace {

struct Scenario {
  std::vector<lie::SE3> poses;  ///< in a world frame tilted by R_tilt
  std::vector<Preintegrator> increments;
  std::vector<Vector3> v_tilted;
};

/// WavyMotion seen in a frame tilted by R_tilt (as a scan-to-map odometry started with a wrong
/// attitude sees it): 10 Hz poses over 2 s (turning by 25 deg about the vertical) and IMU
/// increments between them from readings with an accelerometer bias, integrated at a zero bias.
Scenario tiltedScenario(const lie::SO3& R_tilt, double pose_noise_m = 0.0,
                        const Vector3& accel_bias_mps2 = Vector3::Zero()) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n(0.0, 1.0);
  Scenario s;
  const double dt_pose = 0.1, dt_imu = 0.001;
  for (int k = 0; k <= 20; ++k) {
    const double t = 1.0 + k * dt_pose;
    const NavState truth = test::WavyMotion::state(t);
    const Vector3 noise = pose_noise_m * Vector3(n(rng), n(rng), n(rng));
    s.poses.emplace_back(R_tilt * truth.R_world_body, R_tilt * truth.p_world + noise);
    s.v_tilted.push_back(R_tilt * truth.v_world);
    if (k == 20) break;
    Preintegrator pre({}, ImuNoise{});
    for (int i = 0; i < 100; ++i) {
      const double t_mid = t + (i + 0.5) * dt_imu;
      pre.integrate(test::WavyMotion::accel(t_mid) + accel_bias_mps2, test::WavyMotion::gyro(t_mid),
                    dt_imu);
    }
    s.increments.push_back(pre);
  }
  return s;
}

TEST(GravityAlignment, FindsGravityAndVelocitiesInATiltedFrame) {
  const lie::SO3 R_tilt =
      lie::SO3::fromRollPitchYaw(4 * kRadPerDeg, -6 * kRadPerDeg, 30 * kRadPerDeg);
  const Scenario s = tiltedScenario(R_tilt);
  const GravityAlignment a = alignGravity(s.poses, s.increments, 9.81);
  const Vector3 g_true = R_tilt * test::kGravityWorld;
  EXPECT_LT(std::acos(a.gravity_world.normalized().dot(g_true.normalized())), 0.02 * kRadPerDeg);
  EXPECT_NEAR(a.estimated_magnitude_mps2, 9.81, 0.01);
  ASSERT_EQ(a.v_world.size(), s.poses.size());
  for (std::size_t k = 0; k < s.poses.size(); ++k)
    EXPECT_LT((a.v_world[k] - s.v_tilted[k]).norm(), 0.005) << k;
  // Levelling undoes the tilt (up to a heading, which gravity cannot tell).
  const Vector3 up = (a.R_levelled_world * R_tilt) * Vector3::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up.z())), 0.02 * kRadPerDeg);
}

TEST(GravityAlignment, NoisyPosesStillGiveTheTiltToAFractionOfADegree) {
  const lie::SO3 R_tilt = lie::SO3::fromRollPitchYaw(-3 * kRadPerDeg, 5 * kRadPerDeg, 0.0);
  const Scenario s = tiltedScenario(R_tilt, 0.01);
  const GravityAlignment a = alignGravity(s.poses, s.increments, 9.81);
  const Vector3 g_true = R_tilt * test::kGravityWorld;
  EXPECT_LT(std::acos(a.gravity_world.normalized().dot(g_true.normalized())), 0.5 * kRadPerDeg);
  EXPECT_NEAR(a.estimated_magnitude_mps2, 9.81, 0.3);
}

double angleDeg(const Vector3& a, const Vector3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) / kRadPerDeg;
}

TEST(GravityAlignment, TellsAnAccelerometerBiasFromATiltWhenTheRigTurns) {
  const lie::SO3 R_tilt =
      lie::SO3::fromRollPitchYaw(4 * kRadPerDeg, -6 * kRadPerDeg, 30 * kRadPerDeg);
  const Vector3 bias(0.15, -0.10, 0.08);
  const Scenario s = tiltedScenario(R_tilt, 0.0, bias);
  const Vector3 g_true = R_tilt * test::kGravityWorld;
  // Taking the increments' bias as exact puts the bias into the tilt (0.15 m/s^2 ~ 0.9 deg).
  const GravityAlignment taken = alignGravity(s.poses, s.increments, 9.81);
  EXPECT_GT(angleDeg(taken.gravity_world, g_true), 0.3);
  // Estimated under a wide prior, both come out of exact poses. Over these 2 s the rig turns by
  // 25 deg, which tells a horizontal bias from a tilt only weakly: under the odometry's prior
  // (0.3 m/s^2) most of it stays in the tilt (0.9 deg measured), as on a real start.
  const GravityAlignment joint = alignGravity(s.poses, s.increments, 9.81, 10.0);
  EXPECT_LT(angleDeg(joint.gravity_world, g_true), 0.05);
  EXPECT_LT((joint.accel_bias_mps2 - bias).norm(), 0.01) << joint.accel_bias_mps2.transpose();
  for (std::size_t k = 0; k < s.poses.size(); ++k)
    EXPECT_LT((joint.v_world[k] - s.v_tilted[k]).norm(), 0.005) << k;
}

TEST(GravityAlignment, AnEstimatedBiasStaysNearZeroWithoutOneAndNoisyPoses) {
  const lie::SO3 R_tilt = lie::SO3::fromRollPitchYaw(-3 * kRadPerDeg, 5 * kRadPerDeg, 0.0);
  const Scenario exact = tiltedScenario(R_tilt);
  const GravityAlignment a = alignGravity(exact.poses, exact.increments, 9.81, 0.3);
  const Vector3 g_true = R_tilt * test::kGravityWorld;
  EXPECT_LT(angleDeg(a.gravity_world, g_true), 0.02);
  EXPECT_LT(a.accel_bias_mps2.norm(), 0.005);
  const Scenario noisy = tiltedScenario(R_tilt, 0.01);
  const GravityAlignment n = alignGravity(noisy.poses, noisy.increments, 9.81, 0.3);
  EXPECT_LT(angleDeg(n.gravity_world, g_true), 1.0);
  EXPECT_LT(n.accel_bias_mps2.norm(), 0.2);
}

TEST(GravityAlignment, RejectsTooFewPoses) {
  const Scenario s = tiltedScenario(lie::SO3());
  EXPECT_THROW(alignGravity(std::span(s.poses).first(2), std::span(s.increments).first(1), 9.81),
               std::invalid_argument);
  EXPECT_THROW(alignGravity(s.poses, std::span(s.increments).first(3), 9.81),
               std::invalid_argument);
}

}  // namespace
}  // namespace taiga::imu
