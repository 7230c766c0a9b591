// The health monitor on hand-made evidence: a run's own history is the yardstick for fitness and
// inlier share; a rejected factor degrades a scan; no ok scan for longer than lost_after_s loses
// the track, recovery takes recovery_scans ok scans in a row; an impossible speed loses it at
// once; a long loss asks for a new local map.
#include "../../src/pipeline/health_monitor.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace taiga::pipeline {
namespace {

using ::testing::HasSubstr;

constexpr double kPeriod_s = 0.1;
constexpr double kMaxFitness_m2 = 2.0;  // OdometryConfig::max_fitness_m2

HealthEvidence goodScan(double t_s) {
  return {.t_s = t_s,
          .registered = true,
          .lidar = LidarFactor::kUsed,
          .fitness_m2 = 0.05,
          .inlier_share = 0.9,
          .v_odom = Eigen::Vector3d(1.0, 0.0, 0.0),
          .estimates_bias = true};
}

HealthEvidence rejectedScan(double t_s) {
  HealthEvidence scan = goodScan(t_s);
  scan.lidar = LidarFactor::kRejected;
  scan.lidar_note = "fitness 3.000 m^2 above 2.000";
  return scan;
}

/// Feeds `n` good scans from t = 0; returns the next scan's time.
double warmUp(HealthMonitor& monitor, int n) {
  for (int k = 0; k < n; ++k)
    EXPECT_EQ(monitor.judge(goodScan(k * kPeriod_s)).status, ScanStatus::kOk);
  return n * kPeriod_s;
}

TEST(HealthMonitor, GoodScansAreOk) {
  HealthMonitor monitor(HealthConfig{}, kMaxFitness_m2);
  warmUp(monitor, 50);
}

TEST(HealthMonitor, FitnessFarAboveTheRunsOwnMedianIsDegraded) {
  HealthMonitor monitor(HealthConfig{}, kMaxFitness_m2);
  const double t_s = warmUp(monitor, 10);
  HealthEvidence scan = goodScan(t_s);
  scan.fitness_m2 = 0.3;  // 6x the median 0.05, below every absolute limit
  const ScanHealth health = monitor.judge(scan);
  EXPECT_EQ(health.status, ScanStatus::kDegraded);
  EXPECT_THAT(health.reason, HasSubstr("recent median"));
  // Twice the median is within the run's normal spread.
  scan.t_s += kPeriod_s;
  scan.fitness_m2 = 0.1;
  EXPECT_EQ(monitor.judge(scan).status, ScanStatus::kOk);
}

TEST(HealthMonitor, ScansItDistrustsNeverBecomeTheYardstick) {
  HealthConfig config;
  config.lost_after_s = 0.5;
  HealthMonitor monitor(config, kMaxFitness_m2);
  double t_s = warmUp(monitor, 10);
  // From now on every scan fits ten times worse and matches a tenth as much (a registration that
  // went wrong and stays wrong): degraded, then lost, and never ok again.
  std::vector<ScanStatus> statuses;
  for (int k = 0; k < 30; ++k, t_s += kPeriod_s) {
    HealthEvidence scan = goodScan(t_s);
    scan.fitness_m2 = 0.5;
    scan.inlier_share = 0.09;
    statuses.push_back(monitor.judge(scan).status);
  }
  EXPECT_EQ(statuses.front(), ScanStatus::kDegraded);
  EXPECT_EQ(std::count(statuses.begin(), statuses.end(), ScanStatus::kOk), 0);
  EXPECT_EQ(statuses.back(), ScanStatus::kLost);
}

TEST(HealthMonitor, ScansFromTheKeyframesOwnViewpointNeverBecomeTheFitnessYardstick) {
  // A rig standing on its first keyframe for 3 s matches its own points (fitness 0.03 m^2);
  // driving off, a sparse map fits 0.3 m on at 0.15 m^2, and further on at up to 0.3 m^2.
  HealthMonitor monitor(HealthConfig{}, kMaxFitness_m2);
  double t_s = 0.0;
  for (int k = 0; k < 30; ++k, t_s += kPeriod_s) {
    HealthEvidence standing = goodScan(t_s);
    standing.fitness_m2 = 0.03;
    standing.at_keyframe_viewpoint = true;
    EXPECT_EQ(monitor.judge(standing).status, ScanStatus::kOk);
  }
  EXPECT_TRUE(monitor.hasYardstick()) << "a working registration, though no fitness yardstick";
  // Their inlier share is a yardstick: a scan driving off that matches a third as much is not ok.
  HealthEvidence unmatched = goodScan(t_s);
  unmatched.inlier_share = 0.3;
  EXPECT_EQ(monitor.judge(unmatched).status, ScanStatus::kDegraded);
  t_s += kPeriod_s;
  for (int k = 0; k < 30; ++k, t_s += kPeriod_s) {
    HealthEvidence moving = goodScan(t_s);
    moving.fitness_m2 = 0.15 + 0.005 * k;
    EXPECT_EQ(monitor.judge(moving).status, ScanStatus::kOk) << "moving scan " << k;
  }
  // The yardstick the moving scans taught still finds a registration gone wrong.
  HealthEvidence wrong = goodScan(t_s);
  wrong.fitness_m2 = 1.5;
  EXPECT_EQ(monitor.judge(wrong).status, ScanStatus::kDegraded);
  // And a stop on a keyframe later in the run keeps it: standing scans do not displace it.
  for (int k = 0; k < 30; ++k) {
    HealthEvidence standing = goodScan(t_s += kPeriod_s);
    standing.fitness_m2 = 0.03;
    standing.at_keyframe_viewpoint = true;
    monitor.judge(standing);
  }
  wrong.t_s = t_s + kPeriod_s;
  EXPECT_EQ(monitor.judge(wrong).status, ScanStatus::kDegraded);
}

TEST(HealthMonitor, AFewMatchedPointsAreDegraded) {
  HealthMonitor monitor(HealthConfig{}, kMaxFitness_m2);
  HealthEvidence scan = goodScan(warmUp(monitor, 10));
  scan.inlier_share = 0.3;  // recently 90 %
  const ScanHealth health = monitor.judge(scan);
  EXPECT_EQ(health.status, ScanStatus::kDegraded);
  EXPECT_THAT(health.reason, HasSubstr("30 % of the points matched"));
}

TEST(HealthMonitor, NoHistoryNoRelativeJudgement) {
  HealthMonitor monitor(HealthConfig{}, kMaxFitness_m2);
  HealthEvidence scan = goodScan(0.0);
  scan.fitness_m2 = 1.0;
  EXPECT_EQ(monitor.judge(scan).status, ScanStatus::kOk);
}

TEST(HealthMonitor, RejectedFactorsDegradeThenLoseTheTrackThenRecover) {
  HealthConfig config;
  config.lost_after_s = 0.5;
  config.recovery_scans = 3;
  config.reinitialize_after_s = 100.0;
  HealthMonitor monitor(config, kMaxFitness_m2);
  double t_s = warmUp(monitor, 10);
  const double last_ok_s = 9 * kPeriod_s;  // as warmUp stamped it
  std::vector<ScanStatus> statuses;
  for (int k = 0; k < 8; ++k, t_s += kPeriod_s) {
    const ScanHealth health = monitor.judge(rejectedScan(t_s));
    statuses.push_back(health.status);
    if (t_s - last_ok_s <= config.lost_after_s) {
      EXPECT_EQ(health.status, ScanStatus::kDegraded) << t_s;
      EXPECT_THAT(health.reason, HasSubstr("lidar factor rejected: fitness 3.000"));
    } else {
      EXPECT_EQ(health.status, ScanStatus::kLost) << t_s;
      EXPECT_THAT(health.reason, HasSubstr("no scan ok for"));
    }
  }
  EXPECT_EQ(statuses.front(), ScanStatus::kDegraded);
  EXPECT_EQ(statuses.back(), ScanStatus::kLost);
  EXPECT_FALSE(monitor.restartLocalMap());
  // Good scans again: lost until three in a row, then ok and saying so.
  for (int k = 1; k < config.recovery_scans; ++k, t_s += kPeriod_s) {
    const ScanHealth health = monitor.judge(goodScan(t_s));
    EXPECT_EQ(health.status, ScanStatus::kLost);
    EXPECT_THAT(health.reason, HasSubstr("recovering"));
  }
  const ScanHealth recovered = monitor.judge(goodScan(t_s));
  EXPECT_EQ(recovered.status, ScanStatus::kOk);
  EXPECT_THAT(recovered.reason, HasSubstr("recovered"));
  EXPECT_EQ(monitor.judge(goodScan(t_s + kPeriod_s)).reason, "");
}

TEST(HealthMonitor, ABadScanBetweenRecoveringOnesRestartsTheCount) {
  HealthConfig config;
  config.lost_after_s = 0.2;
  config.recovery_scans = 2;
  HealthMonitor monitor(config, kMaxFitness_m2);
  double t_s = warmUp(monitor, 10);
  for (int k = 0; k < 5; ++k, t_s += kPeriod_s) monitor.judge(rejectedScan(t_s));
  EXPECT_EQ(monitor.judge(goodScan(t_s)).status, ScanStatus::kLost);
  t_s += kPeriod_s;
  EXPECT_EQ(monitor.judge(rejectedScan(t_s)).status, ScanStatus::kLost);
  t_s += kPeriod_s;
  EXPECT_EQ(monitor.judge(goodScan(t_s)).status, ScanStatus::kLost);
  t_s += kPeriod_s;
  EXPECT_EQ(monitor.judge(goodScan(t_s)).status, ScanStatus::kOk);
}

TEST(HealthMonitor, ImpossibleSpeedIsLostAtOnce) {
  HealthMonitor monitor(HealthConfig{}, kMaxFitness_m2);
  HealthEvidence scan = goodScan(warmUp(monitor, 10));
  scan.v_odom = Eigen::Vector3d(0.0, 45.0, 0.0);
  const ScanHealth health = monitor.judge(scan);
  EXPECT_EQ(health.status, ScanStatus::kLost);
  EXPECT_THAT(health.reason, HasSubstr("speed 45.0 m/s"));
}

TEST(HealthMonitor, VelocityJumpAndImplausibleBiasesAreDegraded) {
  HealthMonitor monitor(HealthConfig{}, kMaxFitness_m2);
  double t_s = warmUp(monitor, 10);
  HealthEvidence jump = goodScan(t_s);
  jump.v_odom = Eigen::Vector3d(1.0, 5.0, 0.0);  // 5 m/s in 0.1 s: 50 m/s^2
  EXPECT_THAT(monitor.judge(jump).reason, HasSubstr("velocity jumped at 50 m/s^2"));
  HealthEvidence biased = goodScan(t_s + kPeriod_s);
  biased.v_odom = jump.v_odom;
  biased.bias.accel_mps2 = Eigen::Vector3d(0.0, 2.0, 0.0);
  biased.bias.gyro_radps = Eigen::Vector3d(0.0, 0.0, 0.5);  // 28.6 deg/s
  const ScanHealth health = monitor.judge(biased);
  EXPECT_EQ(health.status, ScanStatus::kDegraded);
  EXPECT_THAT(health.reason, HasSubstr("accelerometer bias estimate 2.00"));
  EXPECT_THAT(health.reason, HasSubstr("gyroscope bias estimate 28.6"));
  // Lidar-only: no biases to judge.
  biased.estimates_bias = false;
  biased.t_s += kPeriod_s;
  EXPECT_EQ(monitor.judge(biased).status, ScanStatus::kOk);
}

TEST(HealthMonitor, LostForLongAsksForANewLocalMap) {
  HealthConfig config;
  config.lost_after_s = 0.5;
  config.reinitialize_after_s = 1.0;
  HealthMonitor monitor(config, kMaxFitness_m2);
  double t_s = warmUp(monitor, 10);
  const double last_ok_s = 9 * kPeriod_s;  // as warmUp stamped it
  bool asked = false;
  for (; t_s < last_ok_s + 3.0 && !asked; t_s += kPeriod_s) {
    monitor.judge(rejectedScan(t_s));
    asked = monitor.restartLocalMap();
  }
  ASSERT_TRUE(asked);
  EXPECT_GT(t_s - kPeriod_s - last_ok_s, config.lost_after_s + config.reinitialize_after_s);
  monitor.localMapRestarted(t_s);
  EXPECT_FALSE(monitor.restartLocalMap());
  // The new map's first scan has nothing to register to; still lost until recovered.
  HealthEvidence seed = goodScan(t_s);
  seed.registered = false;
  EXPECT_EQ(monitor.judge(seed).status, ScanStatus::kLost);
}

}  // namespace
}  // namespace taiga::pipeline
