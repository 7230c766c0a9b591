#include "taiga/pipeline/imu_buffer.hpp"

#include <gtest/gtest.h>

#include "../imu/imu_test_motion.hpp"
#include "taiga/imu/propagation.hpp"

namespace taiga::pipeline {
namespace {

using imu::test::kGravityWorld;
using imu::test::WavyMotion;

ImuBuffer wavyBuffer(double t0, double t1, double rate_hz) {
  ImuBuffer buffer;
  for (double t = t0; t <= t1; t += 1.0 / rate_hz)
    buffer.add({t, WavyMotion::accel(t + 0.5 / rate_hz), WavyMotion::gyro(t + 0.5 / rate_hz), {}});
  return buffer;
}

TEST(ImuBuffer, PreintegrationAndPropagationReadTheSameSignal) {
  // Between scan times that fall between readings, the preintegrated prediction and the
  // propagated state must be the same state: deskewing and the IMU factor see one motion.
  const ImuBuffer buffer = wavyBuffer(0.0, 2.0, 400.0);
  const double t0 = 0.5013, t1 = 0.6021;
  const imu::ImuBias bias{{0.01, 0.02, -0.01}, {0.001, 0.0, -0.002}};
  const imu::NavState start = WavyMotion::state(t0);
  const imu::NavState predicted =
      buffer.preintegrate(t0, t1, bias, imu::ImuNoise{}).predict(start, bias, kGravityWorld);
  const auto states =
      imu::propagateThrough(start, t0, t1, buffer.signalOver(t0, t1), bias, kGravityWorld);
  EXPECT_LT((predicted.p_world - states.back().state.p_world).norm(), 1e-10);
  EXPECT_LT((predicted.v_world - states.back().state.v_world).norm(), 1e-10);
  EXPECT_LT((predicted.R_world_body.inverse() * states.back().state.R_world_body).angle(), 1e-10);
  EXPECT_NEAR(buffer.preintegrate(t0, t1, bias, imu::ImuNoise{}).deltaTime(), t1 - t0, 1e-12);
}

TEST(ImuBuffer, KeepsTheReadingInForceWhenDroppingAndIgnoresRepeatedTimes) {
  ImuBuffer buffer = wavyBuffer(0.0, 1.0, 100.0);
  EXPECT_FALSE(buffer.add({0.5, {}, {}, {}}));  // not after the last reading
  buffer.dropBefore(0.505);
  EXPECT_NEAR(buffer.firstTime(), 0.5, 1e-9);  // the reading held over 0.505
  const std::vector<ImuSample> readings = buffer.between(0.505, 0.535);
  ASSERT_EQ(readings.size(), 4u);                         // 0.50, 0.51, 0.52, 0.53
  EXPECT_EQ(buffer.signalOver(0.505, 0.535).size(), 5u);  // and 0.54, the one after the interval
  EXPECT_NEAR(readings.front().t_s, 0.5, 1e-9);
}

TEST(ImuBuffer, MeasuresTheLongestStretchWithoutReadings) {
  ImuBuffer buffer;
  for (double t : {0.00, 0.01, 0.02, 0.50, 0.51}) buffer.add({t, {}, {}, {}});
  EXPECT_NEAR(buffer.longestGap(0.005, 0.015), 0.005, 1e-12);  // regular readings
  EXPECT_NEAR(buffer.longestGap(0.015, 0.505), 0.48, 1e-12);   // the gap 0.02-0.50
  EXPECT_NEAR(buffer.longestGap(0.1, 0.2), 0.1, 1e-12);        // wholly inside the gap
  EXPECT_NEAR(buffer.longestGap(0.505, 0.9), 0.39, 1e-12);     // after the last reading
}

}  // namespace
}  // namespace taiga::pipeline
