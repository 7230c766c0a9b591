#include "taiga/imu/propagation.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "imu_test_motion.hpp"

namespace taiga::imu {
namespace {

using test::kGravityWorld;
using test::WavyMotion;

std::vector<ImuSample> wavySamples(double t_first, double t_last, double rate_hz,
                                   const ImuBias& bias = {}) {
  std::vector<ImuSample> samples;
  for (double t = t_first; t <= t_last + 1e-12; t += 1.0 / rate_hz) {
    // The reading held from t to t + dt is the motion's value at the middle of that step.
    const double t_mid = t + 0.5 / rate_hz;
    samples.push_back({t,
                       WavyMotion::accel(t_mid) + bias.accel_mps2,
                       WavyMotion::gyro(t_mid) + bias.gyro_radps,
                       {}});
  }
  return samples;
}

TEST(Propagation, FollowsTheTrueMotionThroughAScan) {
  const ImuBias bias{{0.2, -0.1, 0.05}, {0.01, 0.02, -0.03}};
  const std::vector<ImuSample> samples = wavySamples(0.0, 2.0, 2000.0, bias);
  const double t_start = 1.0003, t_end = 1.1003;  // between sample times, as scans are
  const auto states =
      propagateThrough(WavyMotion::state(t_start), t_start, t_end, samples, bias, kGravityWorld);
  ASSERT_GE(states.size(), 200u);
  EXPECT_DOUBLE_EQ(states.front().t_s, t_start);
  EXPECT_DOUBLE_EQ(states.back().t_s, t_end);
  for (std::size_t k = 1; k < states.size(); ++k) {
    ASSERT_GT(states[k].t_s, states[k - 1].t_s);
    const NavState truth = WavyMotion::state(states[k].t_s);
    EXPECT_LT((states[k].state.p_world - truth.p_world).norm(), 2e-5) << states[k].t_s;
    EXPECT_LT((states[k].state.R_world_body.inverse() * truth.R_world_body).angle(), 2e-4)
        << states[k].t_s;
  }
  // Every sample time inside the interval is a state time: IMU-rate poses.
  std::size_t inside = 0;
  for (const ImuSample& s : samples) inside += s.t_s > t_start && s.t_s < t_end;
  EXPECT_EQ(states.size(), inside + 2);
}

TEST(Propagation, IgnoringTheBiasDriftsAway) {
  const ImuBias bias{{0.2, -0.1, 0.05}, {0.01, 0.02, -0.03}};
  const std::vector<ImuSample> samples = wavySamples(0.0, 2.0, 500.0, bias);
  const auto states =
      propagateThrough(WavyMotion::state(0.5), 0.5, 1.5, samples, {}, kGravityWorld);
  EXPECT_GT((states.back().state.p_world - WavyMotion::position(1.5)).norm(), 0.05);
}

TEST(Propagation, SamplesStartingLateUseTheFirstReadingAndBadArgumentsThrow) {
  const std::vector<ImuSample> samples = wavySamples(1.0, 1.2, 100.0);
  const auto states =
      propagateThrough(WavyMotion::state(0.99), 0.99, 1.05, samples, {}, kGravityWorld);
  EXPECT_DOUBLE_EQ(states.back().t_s, 1.05);
  EXPECT_LT((states.back().state.p_world - WavyMotion::position(1.05)).norm(), 1e-3);
  EXPECT_THROW(propagateThrough(NavState{}, 1.0, 0.5, samples, {}, kGravityWorld),
               std::invalid_argument);
  EXPECT_THROW(propagateThrough(NavState{}, 0.0, 0.5, {}, {}, kGravityWorld),
               std::invalid_argument);
  const Trajectory trajectory = toTrajectory(states);
  EXPECT_EQ(trajectory.size(), states.size());
}

}  // namespace
}  // namespace taiga::imu
