// The orientation output of the simulated IMU: an attitude filter's estimate with a small, slowly
// varying tilt error and a drifting heading with a constant offset.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "taiga/core/angles.hpp"
#include "taiga/lie/so3.hpp"
#include "taiga/sim/imu.hpp"
#include "taiga/sim/motion.hpp"

namespace taiga::sim {
namespace {

struct AttitudeError {
  double tilt_rad;
  double heading_rad;
};

Motion makeMotion(double duration_s) {
  return Motion(MotionParams{}, duration_s, 1, Terrain(ForestParams{}, 1));
}

/// Reported R_enu_imu relative to the truth: R_reported R_true^-1, expected Rz(psi) Exp([ex, ey, 0]).
Eigen::Matrix3d errorRotation(const ImuSample& sample, const Eigen::Matrix3d& R_enu_body) {
  return sample.orientation->q_reference_imu.toRotationMatrix() * R_enu_body.transpose();
}

TEST(ImuOrientation, OffByDefaultAsInOusterSensors) {
  const Motion motion = makeMotion(10.0);
  ImuSimulator imu(ImuParams{}, 1);
  EXPECT_FALSE(imu.next(motion).orientation.has_value());
}

TEST(ImuOrientation, ExactWithoutNoiseInTheWorldFramesHeading) {
  const Motion motion = makeMotion(20.0);
  ImuParams params;
  params.noise = false;
  params.orientation_output = true;
  const double world_yaw_deg = 30.0;
  ImuSimulator imu(params, 1, world_yaw_deg);
  const Eigen::Matrix3d R_enu_world =
      Eigen::AngleAxisd(world_yaw_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (int k = 0; k < 2000; ++k) {
    const double t = imu.nextTime_s();
    const ImuSample sample = imu.next(motion);
    ASSERT_TRUE(sample.orientation);
    EXPECT_EQ(sample.orientation->reference, OrientationReference::kEnu);
    const Eigen::Matrix3d R_true = R_enu_world * motion.at(t).T_world_body.rotation().matrix();
    const Eigen::Matrix3d R = sample.orientation->q_reference_imu.toRotationMatrix();
    ASSERT_LT((R - R_true).norm(), 1e-12) << t;
  }
}

TEST(ImuOrientation, TiltErrorSmallAndSlowHeadingDriftsFromItsOffset) {
  const double duration_s = 600.0;
  const Motion motion = makeMotion(duration_s);
  ImuParams params;
  params.orientation_output = true;
  ImuSimulator imu(params, 7);
  double tilt_sum_sq = 0.0, max_tilt_step = 0.0, previous_tilt = 0.0;
  double heading_at_start = 0.0, heading_at_end = 0.0;
  int n = 0;
  while (imu.nextTime_s() <= duration_s) {
    const double t = imu.nextTime_s();
    const ImuSample sample = imu.next(motion);
    const Eigen::Matrix3d R_error =
        errorRotation(sample, motion.at(t).T_world_body.rotation().matrix());
    // The error seen in the output is the simulator's own error state, applied on the left.
    const Eigen::Vector3d state = imu.orientationError_rad();
    const Eigen::Matrix3d R_expected =
        Eigen::AngleAxisd(state.z(), Eigen::Vector3d::UnitZ()).toRotationMatrix() *
        lie::SO3::Exp(Eigen::Vector3d(state.x(), state.y(), 0.0)).matrix();
    ASSERT_LT((R_error - R_expected).norm(), 1e-9) << t;
    // Angle between the reported and the true up axis.
    const AttitudeError e{std::acos(std::clamp(R_error(2, 2), -1.0, 1.0)), state.z()};
    tilt_sum_sq += e.tilt_rad * e.tilt_rad;
    if (n > 0) max_tilt_step = std::max(max_tilt_step, std::abs(e.tilt_rad - previous_tilt));
    previous_tilt = e.tilt_rad;
    if (n == 0) heading_at_start = e.heading_rad;
    heading_at_end = e.heading_rad;
    ++n;
  }
  // Tilt: two Gauss-Markov axes of 0.7 deg: RMS 1.0 deg (over 10 correlation times: +-50 %).
  const double tilt_rms_deg = std::sqrt(tilt_sum_sq / n) * kDegPerRad;
  EXPECT_GT(tilt_rms_deg, 0.4);
  EXPECT_LT(tilt_rms_deg, 1.6);
  // Slowly varying: at 200 Hz and tau = 60 s a step is ~0.7 deg x sqrt(2 dt / tau) ~ 0.013 deg.
  EXPECT_LT(max_tilt_step * kDegPerRad, 0.06);
  // Heading: starts at the constant offset, then a random walk of 0.15 deg/sqrt(s): 3.7 deg
  // 1-sigma after 600 s (bounded at 4.5 sigma, and it must have moved).
  EXPECT_NEAR(heading_at_start * kDegPerRad, 35.0, 0.05);
  const double drift_deg = (heading_at_end - heading_at_start) * kDegPerRad;
  EXPECT_LT(std::abs(drift_deg), 4.5 * 0.15 * std::sqrt(duration_s));
  EXPECT_GT(std::abs(drift_deg), 0.05);
  std::cout << "tilt error RMS " << tilt_rms_deg << " deg, heading drift " << drift_deg
            << " deg over " << duration_s << " s\n";
}

TEST(ImuOrientation, AccelerometerAndGyroUnchangedByTheOrientationOutput) {
  const Motion motion = makeMotion(10.0);
  ImuParams with = ImuParams{}, without = ImuParams{};
  with.orientation_output = true;
  ImuSimulator a(with, 3), b(without, 3);
  for (int k = 0; k < 500; ++k) {
    const ImuSample sa = a.next(motion), sb = b.next(motion);
    ASSERT_EQ(sa.acceleration_imu_mps2, sb.acceleration_imu_mps2);
    ASSERT_EQ(sa.angular_velocity_imu_radps, sb.angular_velocity_imu_radps);
  }
}

}  // namespace
}  // namespace taiga::sim
