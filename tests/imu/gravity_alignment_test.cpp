#include "taiga/imu/gravity_alignment.hpp"

#include <gtest/gtest.h>

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
/// attitude sees it): 10 Hz poses over `span_s` (2 s) and exact IMU increments between them.
/// The accelerometer reads `reading_bias` too; the increments are integrated with `bias_hat`.
Scenario tiltedScenario(const lie::SO3& R_tilt, double pose_noise_m = 0.0,
                        const Vector3& bias_hat = Vector3::Zero(),
                        const Vector3& reading_bias = Vector3::Zero(), double span_s = 2.0) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n(0.0, 1.0);
  Scenario s;
  const double dt_pose = 0.1, dt_imu = 0.001;
  const int intervals = static_cast<int>(std::lround(span_s / dt_pose));
  for (int k = 0; k <= intervals; ++k) {
    const double t = 1.0 + k * dt_pose;
    const NavState truth = test::WavyMotion::state(t);
    const Vector3 noise = pose_noise_m * Vector3(n(rng), n(rng), n(rng));
    s.poses.emplace_back(R_tilt * truth.R_world_body, R_tilt * truth.p_world + noise);
    s.v_tilted.push_back(R_tilt * truth.v_world);
    if (k == intervals) break;
    Preintegrator pre(ImuBias{bias_hat, Vector3::Zero()}, ImuNoise{});
    for (int i = 0; i < 100; ++i) {
      const double t_mid = t + (i + 0.5) * dt_imu;
      pre.integrate(test::WavyMotion::accel(t_mid) + reading_bias, test::WavyMotion::gyro(t_mid),
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
  const GravityAlignment a = alignGravity(s.poses, s.increments, 9.81, {});
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
  const GravityAlignment a = alignGravity(s.poses, s.increments, 9.81, {});
  const Vector3 g_true = R_tilt * test::kGravityWorld;
  EXPECT_LT(std::acos(a.gravity_world.normalized().dot(g_true.normalized())), 0.5 * kRadPerDeg);
  EXPECT_NEAR(a.estimated_magnitude_mps2, 9.81, 0.3);
}

TEST(GravityAlignment, EstimatesTheAccelerometerBiasWhateverTheBiasTheIncrementsWereIntegratedWith) {
  // Before levelling, the smoother explains part of the misplaced gravity as accelerometer bias;
  // increments integrated with that bias (0.4 m/s^2: 2.3 deg of tilt) taken as they are would
  // tilt the levelled frame. The alignment estimates the bias (zero here) under its prior.
  const lie::SO3 R_tilt = lie::SO3::fromRollPitchYaw(3 * kRadPerDeg, -2 * kRadPerDeg, 0.0);
  const Vector3 g_true = R_tilt * test::kGravityWorld;
  for (const Vector3& bias_hat : {Vector3(0.4, -0.2, 0.0), Vector3(-0.1, 0.3, 0.2)}) {
    const Scenario s = tiltedScenario(R_tilt, 0.0, bias_hat);
    const GravityAlignment a = alignGravity(s.poses, s.increments, 9.81, {});
    EXPECT_LT(std::acos(a.gravity_world.normalized().dot(g_true.normalized())), 0.05 * kRadPerDeg);
    EXPECT_LT(a.accel_bias_mps2.norm(), 0.01);
  }
}

TEST(GravityAlignment, TellsABiasFromATiltOnlyWhenTheRigTurnsEnough) {
  // The accelerometer reads 0.15 m/s^2 too much on x: 0.9 deg of tilt if taken for gravity.
  // Over 2 s WavyMotion turns by about 25 deg, too little to tell the two apart against the
  // 0 +- 0.1 prior: the tilt takes most of it. Over 12 s it swings through 90 deg of heading and
  // 30 and 20 deg of roll and pitch, and the data find the bias.
  const lie::SO3 R_tilt = lie::SO3::fromRollPitchYaw(-2 * kRadPerDeg, 4 * kRadPerDeg, 0.0);
  const Vector3 g_true = R_tilt * test::kGravityWorld;
  const Vector3 true_bias(0.15, 0.0, 0.0);
  const auto align = [&](double span_s) {
    const Scenario s = tiltedScenario(R_tilt, 0.0, Vector3::Zero(), true_bias, span_s);
    return alignGravity(s.poses, s.increments, 9.81, {});
  };
  const auto tiltErrorDeg = [&](const GravityAlignment& a) {
    return std::acos(a.gravity_world.normalized().dot(g_true.normalized())) / kRadPerDeg;
  };
  const GravityAlignment short_span = align(2.0), long_span = align(12.0);
  EXPECT_GT(tiltErrorDeg(short_span), 0.3);
  EXPECT_LT(tiltErrorDeg(long_span), 0.1);
  EXPECT_NEAR(long_span.accel_bias_mps2.x(), 0.15, 0.02);
}

TEST(GravityAlignment, RejectsTooFewPoses) {
  const Scenario s = tiltedScenario(lie::SO3());
  EXPECT_THROW(alignGravity(std::span(s.poses).first(2), std::span(s.increments).first(1), 9.81, {}),
               std::invalid_argument);
  EXPECT_THROW(alignGravity(s.poses, std::span(s.increments).first(3), 9.81, {}),
               std::invalid_argument);
  EXPECT_THROW(alignGravity(s.poses, s.increments, 9.81, {.sigma_mps2 = 0.0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace taiga::imu
