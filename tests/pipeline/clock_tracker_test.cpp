// The run's clock tracking on synthetic data with a known answer: a body turning about all axes,
// gyro readings on the IMU clock, and registered rotations of scans stamped on a lidar clock whose
// offset drifts. The scans are read with the offset last set (as io::Recording does) and adjusted.
#include "taiga/pipeline/clock_tracker.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace taiga::pipeline {
namespace {

using Eigen::Vector3d;

struct Rig {
  double offset_at_zero_s = 0.010;  ///< the true offset at t = 0 (IMU = lidar clock + offset)
  double drift = 0.0;               ///< d offset / dt (100e-6: 100 ppm)
  double configured_offset_s = 0.010;
  bool turns = true;
};

/// A handheld's sway about all axes, or nothing but noise.
Vector3d trueRate(double t, bool turns) {
  if (!turns) return Vector3d::Zero();
  return {0.5 * std::sin(1.9 * t), 0.4 * std::sin(1.3 * t + 0.5),
          0.6 * std::sin(0.7 * t) + 0.3 * std::sin(2.3 * t + 1.0)};
}

struct Tracked {
  ClockTrackingReport report;
  double applied_end_s = 0.0;
  double true_end_s = 0.0;
};

Tracked track(const Rig& rig, double duration_s, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  auto noise3 = [&](double sigma) {
    return Vector3d(normal(rng), normal(rng), normal(rng)) * sigma;
  };
  constexpr double kFine_s = 0.001;  // the true attitude on a 1 kHz grid of the IMU clock
  std::vector<lie::SO3> attitude{lie::SO3()};
  for (double t = 0.0; t < duration_s + 2.0; t += kFine_s)
    attitude.push_back(attitude.back() *
                       lie::SO3::Exp(trueRate(t + 0.5 * kFine_s, rig.turns) * kFine_s));
  auto at = [&](double t_imu) {
    return attitude[static_cast<std::size_t>(std::lround(t_imu / kFine_s))];
  };

  CalibrationConfig config;
  RigConfig rig_config;
  rig_config.lidar_time_offset_s = rig.configured_offset_s;
  double applied_s = rig.configured_offset_s;
  ClockTracker tracker(config, rig_config, [&](double offset_s) { applied_s = offset_s; });
  double t_gyro = 0.0;
  std::uint64_t index = 0;
  Tracked run;
  for (double t_lidar = 0.5; t_lidar < duration_s; t_lidar += 0.1, ++index) {
    const double t_true = t_lidar + rig.offset_at_zero_s + rig.drift * t_lidar;  // IMU clock
    io::Scan scan;
    scan.index = index;
    scan.lidar_time_offset_s = applied_s;
    scan.t_end_s = t_lidar + applied_s;
    tracker.adjust(scan);  // may apply a new offset: the scan's times follow it
    for (; t_gyro <= scan.t_end_s; t_gyro += 0.005)  // 200 Hz, noise 0.5 mrad/s/sqrt(Hz)
      tracker.onImu({.t_s = t_gyro,
                     .angular_velocity_imu_radps = trueRate(t_gyro, rig.turns) + noise3(0.007)});
    ScanOutcome outcome;
    outcome.scan_index = index;
    outcome.t_s = scan.t_end_s;
    outcome.lidar = LidarFactor::kUsed;
    outcome.registration.T_target_source =
        lie::SE3(at(t_true) * lie::SO3::Exp(noise3(3e-4)), Vector3d::Zero());
    tracker.onScan(outcome, lie::SE3());
    run.true_end_s = rig.offset_at_zero_s + rig.drift * t_lidar;
  }
  run.report = tracker.finish();
  run.applied_end_s = applied_s;
  return run;
}

TEST(ClockTracker, FollowsADriftingLidarClock) {
  // 100 ppm over 150 s: the offset grows by 15 ms from the configured (right at the start) one.
  for (unsigned seed : {1u, 2u}) {
    const Tracked run = track({.drift = 100e-6}, 150.0, seed);
    ASSERT_GE(run.report.windows.size(), 10u);
    EXPECT_EQ(run.report.held, 0u);
    // Without tracking the end would be 15 ms off; the tracker lags by less than a millisecond.
    EXPECT_NEAR(run.applied_end_s, run.true_end_s, 1e-3) << "seed " << seed;
    ASSERT_TRUE(run.report.drift_ppm.has_value());
    EXPECT_NEAR(*run.report.drift_ppm, 100.0, 3.0 * *run.report.drift_sigma_ppm + 2.0);
    EXPECT_LT(*run.report.drift_sigma_ppm, 10.0);
  }
}

TEST(ClockTracker, AWrongOffsetIsCorrectedAndAStableClockStaysPut) {
  // Configured 5 ms off, no drift: the first window finds the missing 5 ms.
  const Tracked run = track({.offset_at_zero_s = 0.015, .configured_offset_s = 0.010}, 80.0, 3);
  EXPECT_NEAR(run.applied_end_s, 0.015, 3e-4);
  ASSERT_TRUE(run.report.drift_ppm.has_value());
  EXPECT_LT(std::abs(*run.report.drift_ppm), 3.0 * *run.report.drift_sigma_ppm + 1.0);
}

TEST(ClockTracker, MotionThatDoesNotShowTheOffsetChangesNothing) {
  const Tracked run = track({.offset_at_zero_s = 0.015, .turns = false}, 60.0, 4);
  ASSERT_FALSE(run.report.windows.empty());
  EXPECT_EQ(run.report.held, run.report.windows.size());
  EXPECT_EQ(run.applied_end_s, 0.010);
  EXPECT_NE(run.report.text.find("held"), std::string::npos);
}

}  // namespace
}  // namespace taiga::pipeline
