// The registrations' rotation increments that the calibration and the clock tracking compare with
// the gyro: only between consecutive measured scans the IMU read through.
#include "taiga/pipeline/rotation_increments.hpp"

#include <gtest/gtest.h>

namespace taiga::pipeline {
namespace {

ScanOutcome measured(std::uint64_t index, double yaw_rad, double imu_gap_s = 0.005) {
  ScanOutcome o;
  o.scan_index = index;
  o.t_s = 0.1 * static_cast<double>(index);
  o.lidar = LidarFactor::kUsed;
  o.health.status = ScanStatus::kOk;
  o.registration.T_target_source = lie::SE3(lie::SO3::fromRollPitchYaw(0.0, 0.0, yaw_rad), {});
  o.imu_gap_s = imu_gap_s;
  return o;
}

TEST(RotationIncrements, ConsecutiveMeasuredScansGiveTheirRotation) {
  RotationIncrements take;
  EXPECT_FALSE(take.take(measured(0, 0.0)));
  const std::optional<calib::RotationIncrement> increment = take.take(measured(1, 0.02));
  ASSERT_TRUE(increment);
  EXPECT_DOUBLE_EQ(increment->t0_s, 0.0);
  EXPECT_DOUBLE_EQ(increment->t1_s, 0.1);
  EXPECT_NEAR(increment->theta_body_rad.z(), 0.02, 1e-12);
}

TEST(RotationIncrements, AnIntervalWithoutImuReadingsIsNotTaken) {
  RotationIncrements take(0.05);
  take.take(measured(0, 0.0));
  EXPECT_FALSE(take.take(measured(1, 0.02, 0.1)));  // the IMU was silent over the whole scan
  EXPECT_TRUE(take.take(measured(2, 0.04)));        // the next interval has its readings again
}

TEST(RotationIncrements, ALostOrSkippedScanBreaksTheChain) {
  RotationIncrements take;
  take.take(measured(0, 0.0));
  ScanOutcome lost = measured(1, 0.02);
  lost.health.status = ScanStatus::kLost;
  EXPECT_FALSE(take.take(lost));
  EXPECT_FALSE(take.take(measured(2, 0.04)));  // its predecessor was not measured
  EXPECT_FALSE(take.take(measured(4, 0.08)));  // not consecutive
  EXPECT_TRUE(take.take(measured(5, 0.10)));
}

}  // namespace
}  // namespace taiga::pipeline
