// The time offset and rotation estimator on synthetic motion with a known answer: gyro readings of
// a body turning about all axes (with bias and white noise), and registration rotations with
// pose noise in a body frame rotated by a known extrinsic error and shifted by a known offset.
#include "taiga/calib/time_rotation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "taiga/core/errors.hpp"

namespace taiga::calib {
namespace {

using Eigen::Vector3d;
constexpr double kDegPerRad = 180.0 / M_PI;

struct Truth {
  double offset_s = 0.020;
  lie::SO3 R_c = lie::SO3::fromRollPitchYaw(0.02, -0.025, 0.03);  // about 2.2 deg
  Vector3d bias_radps{0.01, -0.005, 0.002};
  double gyro_noise_radps = 0.01;  // per reading (0.0005 rad/s/sqrt(Hz) at 400 Hz)
  double pose_noise_rad = 3e-4;    // per registered scan, about 0.02 deg
  bool yaw_only = false;
};

/// Body rate on the IMU's clock: a handheld's sway about all axes (or a vehicle's yaw only).
Vector3d trueRate(double t, bool yaw_only) {
  const Vector3d yaw(0.0, 0.0, 0.6 * std::sin(0.7 * t) + 0.3 * std::sin(2.3 * t + 1.0));
  if (yaw_only) return yaw;
  return yaw + Vector3d(0.5 * std::sin(1.9 * t), 0.4 * std::sin(1.3 * t + 0.5), 0.0);
}

struct Data {
  std::vector<GyroReading> gyro;
  std::vector<RotationIncrement> increments;
};

Data simulate(const Truth& truth, unsigned seed, double duration_s = 30.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  auto noise3 = [&](double sigma) -> Vector3d {
    return Vector3d(normal(rng), normal(rng), normal(rng)) * sigma;
  };
  Data d;
  // True attitude on a 1 kHz grid of the IMU clock (midpoint rule), gyro readings at 400 Hz.
  constexpr double kFine_s = 0.001;
  std::vector<lie::SO3> attitude{lie::SO3()};
  for (double t = 0.0; t < duration_s + 1.0; t += kFine_s)
    attitude.push_back(attitude.back() *
                       lie::SO3::Exp(trueRate(t + 0.5 * kFine_s, truth.yaw_only) * kFine_s));
  for (double t = 0.0; t < duration_s + 1.0; t += 0.0025)
    d.gyro.push_back(
        {t, trueRate(t, truth.yaw_only) + truth.bias_radps + noise3(truth.gyro_noise_radps)});
  auto at = [&](double t_imu) {
    return attitude[static_cast<std::size_t>(std::lround(t_imu / kFine_s))];
  };
  // Registration at 10 Hz, labelled on the odometry's clock (true IMU time - offset), in the
  // configured body frame: R_reg = R_true * R_c (so that dR_true = R_c dR_reg R_c^T).
  std::vector<lie::SO3> registered;
  std::vector<double> labels;
  for (double t = 0.5; t < duration_s; t += 0.1) {
    labels.push_back(t - truth.offset_s);
    registered.push_back(at(t) * truth.R_c * lie::SO3::Exp(noise3(truth.pose_noise_rad)));
  }
  for (std::size_t k = 0; k + 1 < registered.size(); ++k)
    d.increments.push_back(
        {labels[k], labels[k + 1], (registered[k].inverse() * registered[k + 1]).Log()});
  return d;
}

double angleDeg(const lie::SO3& a, const lie::SO3& b) {
  return (a.inverse() * b).angle() * kDegPerRad;
}

TEST(IntegrateGyro, ConstantRateGivesItsRotation) {
  std::vector<GyroReading> gyro;
  for (int i = 0; i <= 100; ++i) gyro.push_back({0.01 * i, Vector3d(0.3, -0.2, 1.0)});
  const lie::SO3 R = integrateGyro(gyro, 0.105, 0.605, Vector3d(0.1, 0.0, 0.0));
  EXPECT_NEAR((R.Log() - 0.5 * Vector3d(0.2, -0.2, 1.0)).norm(), 0.0, 1e-9);
  EXPECT_THROW(integrateGyro(gyro, 0.5, 1.5, Vector3d::Zero()), InputError);
}

TEST(TimeRotation, FindsOffsetRotationAndBias) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Truth truth;
    const Data d = simulate(truth, seed);
    const TimeRotationEstimate e = estimateTimeRotation(d.increments, d.gyro);
    EXPECT_TRUE(e.offset_observable);
    EXPECT_TRUE(e.rotation_observable.all());
    EXPECT_NEAR(e.offset_s, truth.offset_s, 0.0005) << "seed " << seed;
    EXPECT_LT(angleDeg(e.R_correction, truth.R_c), 0.05) << "seed " << seed;
    EXPECT_LT((e.gyro_bias_radps - truth.bias_radps).norm(), 0.002) << "seed " << seed;
    EXPECT_TRUE(e.advice.empty());
    // The cost curve has its minimum at the estimate's grid point.
    const auto best = std::min_element(e.cost_curve.begin(), e.cost_curve.end(),
                                       [](auto& a, auto& b) { return a.rms_radps < b.rms_radps; });
    EXPECT_NEAR(best->offset_s, truth.offset_s, 0.0015);
  }
}

TEST(TimeRotation, FindsAGrossMountingError) {
  Truth truth;
  truth.R_c = lie::SO3::fromRollPitchYaw(M_PI, 0.0, M_PI / 2.0);  // upside down and turned 90 deg
  truth.offset_s = -0.035;
  const Data d = simulate(truth, 4);
  const TimeRotationEstimate e = estimateTimeRotation(d.increments, d.gyro);
  EXPECT_LT(angleDeg(e.R_correction, truth.R_c), 0.05);
  EXPECT_NEAR(e.offset_s, truth.offset_s, 0.0005);
}

TEST(TimeRotation, YawOnlyMotionHoldsTheUnexcitedRotation) {
  Truth truth;
  truth.yaw_only = true;
  const Data d = simulate(truth, 5);
  const TimeRotationEstimate e = estimateTimeRotation(d.increments, d.gyro);
  // Turning about z alone shows the tilt of the lidar's z axis (rotation about x and y) but
  // not the rotation about z itself: that is held at the configured value and reported.
  EXPECT_TRUE(e.rotation_observable(0));
  EXPECT_TRUE(e.rotation_observable(1));
  EXPECT_FALSE(e.rotation_observable(2));
  EXPECT_NEAR(e.R_correction.Log().z(), 0.0, 1e-4);
  EXPECT_NEAR(e.R_correction.Log().x(), truth.R_c.Log().x(), 0.002);
  EXPECT_NE(e.advice.find("z axis"), std::string::npos) << e.advice;
  EXPECT_NEAR(e.offset_s, truth.offset_s, 0.001);
}

TEST(TimeRotation, NoMotionIsReportedNotGuessed) {
  Truth truth;
  Data d = simulate(truth, 6);
  // Standing still: the gyro reads its bias and noise, the registration its noise.
  std::mt19937_64 rng(6);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto noise3 = [&](double sigma) -> Vector3d {
    return Vector3d(normal(rng), normal(rng), normal(rng)) * sigma;
  };
  for (GyroReading& g : d.gyro)
    g.omega_body_radps = truth.bias_radps + noise3(truth.gyro_noise_radps);
  for (RotationIncrement& inc : d.increments) inc.theta_body_rad = noise3(truth.pose_noise_rad);
  const TimeRotationEstimate e = estimateTimeRotation(d.increments, d.gyro);
  EXPECT_FALSE(e.offset_observable);
  EXPECT_FALSE(e.rotation_observable.any());
  EXPECT_EQ(e.offset_s, 0.0);
  EXPECT_LT(e.R_correction.angle(), 1e-9);
  EXPECT_LT((e.gyro_bias_radps - truth.bias_radps).norm(), 0.002);
  EXPECT_FALSE(e.advice.empty());
}

TEST(TimeRotation, FailedRegistrationsAreDropped) {
  const Truth truth;
  Data d = simulate(truth, 7);
  for (std::size_t k = 10; k < d.increments.size(); k += 37)
    d.increments[k].theta_body_rad += Vector3d(0.2, -0.1, 0.3);  // a registration 20 deg off
  const TimeRotationEstimate e = estimateTimeRotation(d.increments, d.gyro);
  EXPECT_GE(e.increments_dropped, 7u);
  EXPECT_NEAR(e.offset_s, truth.offset_s, 0.0005);
  EXPECT_LT(angleDeg(e.R_correction, truth.R_c), 0.05);
}

TEST(TimeRotation, SigmasAreHonest) {
  // Over 40 seeds the true error lies within 2 sigma in at least 85 % of the cases (the issue's
  // criterion): of the offsets, and of the rotation errors about each axis.
  int offset_within = 0, rotation_within = 0, runs = 40;
  for (int seed = 100; seed < 100 + runs; ++seed) {
    const Truth truth;
    const Data d = simulate(truth, static_cast<unsigned>(seed), 15.0);
    const TimeRotationEstimate e = estimateTimeRotation(d.increments, d.gyro);
    offset_within += std::abs(e.offset_s - truth.offset_s) <= 2.0 * e.offset_sigma_s;
    const Vector3d error = (truth.R_c.inverse() * e.R_correction).Log();
    rotation_within += (error.cwiseAbs().array() <= 2.0 * e.rotation_sigma_rad.array()).count();
  }
  EXPECT_GE(offset_within, 0.85 * runs);
  EXPECT_GE(rotation_within, 0.85 * 3 * runs);
}

TEST(TimeRotation, TooFewIncrementsIsAnError) {
  const Data d = simulate(Truth{}, 8, 2.0);
  EXPECT_THROW(estimateTimeRotation(d.increments, d.gyro), InputError);
}

}  // namespace
}  // namespace taiga::calib
