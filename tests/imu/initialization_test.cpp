#include "taiga/imu/initialization.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "imu_test_motion.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::imu {
namespace {

/// Readings of a sensor at rest with orientation R_world_body, gyro bias and white noise.
std::vector<ImuSample> restingSamples(const lie::SO3& R_world_body, const Vector3& gyro_bias,
                                      double accel_scale = 1.0) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<ImuSample> samples;
  for (int k = 0; k < 400; ++k) {
    ImuSample s;
    s.t_s = 100.0 + k * 0.005;
    s.acceleration_imu_mps2 = accel_scale * (R_world_body.inverse() * Vector3(0, 0, 9.81) +
                                             0.02 * Vector3(n(rng), n(rng), n(rng)));
    s.angular_velocity_imu_radps = gyro_bias + 0.002 * Vector3(n(rng), n(rng), n(rng));
    samples.push_back(s);
  }
  return samples;
}

double tiltError(const lie::SO3& estimate, const lie::SO3& truth) {
  // Compare the directions of gravity in the body frame: heading is not observable.
  return std::acos(std::clamp(
      (estimate.inverse() * Vector3::UnitZ()).dot(truth.inverse() * Vector3::UnitZ()), -1.0, 1.0));
}

TEST(Initialization, AtRestFindsTiltAndGyroBias) {
  const lie::SO3 R_true =
      lie::SO3::fromRollPitchYaw(8 * kRadPerDeg, -5 * kRadPerDeg, 40 * kRadPerDeg);
  const Vector3 gyro_bias(0.01, -0.004, 0.007);
  const InitialState init = initializeFromImu(restingSamples(R_true, gyro_bias));
  EXPECT_TRUE(init.at_rest);
  EXPECT_FALSE(init.from_orientation);
  EXPECT_LT(tiltError(init.state.R_world_body, R_true), 0.1 * kRadPerDeg);
  EXPECT_LT((init.bias.gyro_radps - gyro_bias).norm(), 5e-4);
  EXPECT_NEAR(init.state.R_world_body.matrix()(1, 0), 0.0, 1e-9);  // zero heading
  EXPECT_TRUE(init.state.v_world.isZero());
  EXPECT_LT(init.covariance(6, 6), 1e-3);  // confident zero velocity at rest
  EXPECT_NEAR(init.t_s, 101.0, 0.01);
}

TEST(Initialization, MovingFromTheStartGivesAnApproximateTiltAndLoosePriors) {
  std::vector<ImuSample> samples;
  for (int k = 0; k < 400; ++k) {
    const double t = k * 0.005;
    samples.push_back({t, test::WavyMotion::accel(t), test::WavyMotion::gyro(t), {}});
  }
  const InitialState init = initializeFromImu(samples);
  EXPECT_FALSE(init.at_rest);
  // The motion tilts by up to 20 degrees and accelerates at up to 1.3 m/s^2: the mean specific
  // force gives the tilt of the window's middle to a few degrees.
  EXPECT_LT(tiltError(init.state.R_world_body, test::WavyMotion::state(0.5).R_world_body),
            8 * kRadPerDeg);
  EXPECT_GE(init.covariance(6, 6), 0.5);
  EXPECT_GE(init.covariance(3, 3), std::pow(2.0 * kRadPerDeg, 2));
}

TEST(Initialization, MovingUsesAnEnuOrientationWholeAndTurnsNedIntoEnu) {
  std::vector<ImuSample> samples;
  for (int k = 0; k < 400; ++k) {
    const double t = k * 0.005;
    samples.push_back({t, test::WavyMotion::accel(t), test::WavyMotion::gyro(t), {}});
  }
  // The orientation output tells the attitude at each reading; the state is the last one's.
  const auto R_enu_imu = [](double t_s) { return test::WavyMotion::state(t_s).R_world_body; };
  for (ImuSample& s : samples)
    s.orientation = ImuOrientation{R_enu_imu(s.t_s).quaternion(), OrientationReference::kEnu};
  const InitialState from_enu = initializeFromImu(samples);
  EXPECT_FALSE(from_enu.at_rest);
  EXPECT_TRUE(from_enu.from_orientation);
  EXPECT_LT((from_enu.state.R_world_body.inverse() * R_enu_imu(from_enu.t_s)).angle(), 1e-9);

  Matrix3 R_ned_enu;
  R_ned_enu << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  for (ImuSample& s : samples) {
    const lie::SO3 R_ned_imu = lie::SO3::fromMatrix(R_ned_enu * R_enu_imu(s.t_s).matrix());
    s.orientation = ImuOrientation{R_ned_imu.quaternion(), OrientationReference::kNed};
  }
  const InitialState from_ned = initializeFromImu(samples);
  EXPECT_LT((from_ned.state.R_world_body.inverse() * R_enu_imu(from_ned.t_s)).angle(), 1e-9);
}

TEST(Initialization, AtRestTheTiltComesFromTheAccelerometerAndTheHeadingFromTheOrientation) {
  const double roll = 3 * kRadPerDeg, pitch = 2 * kRadPerDeg, yaw = 70 * kRadPerDeg;
  const lie::SO3 R_enu_imu = lie::SO3::fromRollPitchYaw(roll, pitch, yaw);
  std::vector<ImuSample> samples = restingSamples(R_enu_imu, Vector3::Zero());
  // An orientation filter's tilt a degree off, as the simulated 9-axis IMUs' are.
  const lie::SO3 R_output =
      lie::SO3::fromRollPitchYaw(roll + 1 * kRadPerDeg, pitch - 1 * kRadPerDeg, yaw);
  for (ImuSample& s : samples)
    s.orientation = ImuOrientation{R_output.quaternion(), OrientationReference::kEnu};
  const InitialState init = initializeFromImu(samples);
  EXPECT_TRUE(init.at_rest);
  EXPECT_TRUE(init.from_orientation);
  EXPECT_LT(tiltError(init.state.R_world_body, R_enu_imu), 0.05 * kRadPerDeg);
  EXPECT_NEAR(init.state.R_world_body.yaw(), yaw, 0.01 * kRadPerDeg);
}

TEST(Initialization, AccelerationsInGAndTooFewReadingsAreClearErrors) {
  const std::vector<ImuSample> in_g = restingSamples(lie::SO3(), Vector3::Zero(), 1.0 / 9.81);
  try {
    initializeFromImu(in_g);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rig.imu_acceleration_unit"), std::string::npos)
        << e.what();
  }
  const std::vector<ImuSample> few(in_g.begin(), in_g.begin() + 5);
  EXPECT_THROW(initializeFromImu(few), InputError);
}

}  // namespace
}  // namespace taiga::imu
