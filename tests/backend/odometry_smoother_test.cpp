// The odometry graph on a known motion: noisy IMU readings with constant unknown biases and noisy
// 10 Hz pose measurements (as registration would give); the smoother must track the pose, recover
// velocity and biases, and report a covariance that matches its actual errors.
#include "taiga/backend/odometry_smoother.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../imu/imu_test_motion.hpp"
#include "taiga/core/angles.hpp"

namespace taiga::backend {
namespace {

using imu::test::kGravityWorld;
using imu::test::WavyMotion;

struct RunStatistics {
  double position_rms_m = 0.0;
  double velocity_rms_mps = 0.0;
  double rotation_rms_rad = 0.0;
  double position_nees = 0.0;  ///< mean normalized estimation error squared of the position (3 dof)
  imu::ImuBias final_bias;
  Eigen::Vector2d tilt_rad = Eigen::Vector2d::Zero();  ///< the estimated frame tilt at the end
};

constexpr double kImuRate = 200.0, kScanRate = 10.0;
const imu::ImuBias kTrueBias{{0.08, -0.05, 0.06}, {0.004, -0.003, 0.005}};
const imu::ImuNoise kNoise{.accel_noise_density = 0.01,
                           .gyro_noise_density = 0.001,
                           .accel_bias_random_walk = 1e-3,
                           .gyro_bias_random_walk = 1e-4};
constexpr double kPoseSigmaM = 0.01, kPoseSigmaRad = 0.002;

/// The poses are measured in a frame tilted by Exp([frame_tilt; 0]) against the IMU's world (a
/// levelling that was off); the smoother estimates that tilt when tilt_sigma_rad > 0.
RunStatistics runSmoother(int window_states, double duration_s,
                          double skip_measurements_from_s = 1e9,
                          double skip_measurements_to_s = 1e9,
                          const Eigen::Vector2d& frame_tilt_rad = Eigen::Vector2d::Zero(),
                          double tilt_sigma_rad = 0.0) {
  const lie::SE3 T_frame_world(
      lie::SO3::Exp(Eigen::Vector3d(frame_tilt_rad.x(), frame_tilt_rad.y(), 0.0)),
      Eigen::Vector3d::Zero());
  auto truthAt = [&](double t) {
    const imu::NavState w = WavyMotion::state(t);
    return imu::NavState{T_frame_world.rotation() * w.R_world_body,
                         T_frame_world.rotation() * w.p_world,
                         T_frame_world.rotation() * w.v_world};
  };
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> unit(0.0, 1.0);
  auto noise3 = [&](double sigma) -> Eigen::Vector3d {
    return Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * sigma;
  };

  OdometrySmoother smoother({.gravity_world = kGravityWorld, .window_states = window_states});
  StateEstimate first{0.0, truthAt(0.0), {}, Matrix15::Zero()};
  first.covariance.diagonal() << Eigen::Vector3d::Constant(1e-4), Eigen::Vector3d::Constant(1e-4),
      Eigen::Vector3d::Constant(1e-2), Eigen::Vector3d::Constant(0.1 * 0.1),
      Eigen::Vector3d::Constant(0.01 * 0.01);
  smoother.initialize(first, tilt_sigma_rad);

  const double imu_dt = 1.0 / kImuRate;
  const int imu_per_scan = static_cast<int>(kImuRate / kScanRate);
  lie::Matrix6 pose_covariance = lie::Matrix6::Zero();
  pose_covariance.diagonal() << Eigen::Vector3d::Constant(kPoseSigmaM * kPoseSigmaM),
      Eigen::Vector3d::Constant(kPoseSigmaRad * kPoseSigmaRad);

  RunStatistics stats;
  int counted = 0;
  const int scans = static_cast<int>(duration_s * kScanRate);
  for (int scan = 1; scan <= scans; ++scan) {
    imu::Preintegrator pre(smoother.latest().bias, kNoise);
    for (int k = 0; k < imu_per_scan; ++k) {
      const double t_mid = ((scan - 1) * imu_per_scan + k + 0.5) * imu_dt;
      pre.integrate(WavyMotion::accel(t_mid) + kTrueBias.accel_mps2 +
                        noise3(kNoise.accel_noise_density / std::sqrt(imu_dt)),
                    WavyMotion::gyro(t_mid) + kTrueBias.gyro_radps +
                        noise3(kNoise.gyro_noise_density / std::sqrt(imu_dt)),
                    imu_dt);
    }
    const double t = scan / kScanRate;
    const imu::NavState truth = truthAt(t);
    std::optional<PoseMeasurement> measurement;
    if (t < skip_measurements_from_s || t > skip_measurements_to_s) {
      const lie::SE3 T_true(truth.R_world_body, truth.p_world);
      const lie::SE3 noisy =
          T_true *
          lie::SE3::Exp((lie::Vector6() << noise3(kPoseSigmaM), noise3(kPoseSigmaRad)).finished());
      measurement = PoseMeasurement{noisy, pose_covariance};
    }
    const StateEstimate estimate = smoother.addState(t, pre, measurement);
    if (t < duration_s / 2) continue;  // statistics after convergence
    const Eigen::Vector3d dp = estimate.state.p_world - truth.p_world;
    stats.position_rms_m += dp.squaredNorm();
    stats.velocity_rms_mps += (estimate.state.v_world - truth.v_world).squaredNorm();
    stats.rotation_rms_rad +=
        std::pow((estimate.state.R_world_body.inverse() * truth.R_world_body).angle(), 2);
    stats.position_nees += dp.dot(estimate.covariance.topLeftCorner<3, 3>().ldlt().solve(dp));
    ++counted;
  }
  stats.position_rms_m = std::sqrt(stats.position_rms_m / counted);
  stats.velocity_rms_mps = std::sqrt(stats.velocity_rms_mps / counted);
  stats.rotation_rms_rad = std::sqrt(stats.rotation_rms_rad / counted);
  stats.position_nees /= counted;
  stats.final_bias = smoother.latest().bias;
  stats.tilt_rad = smoother.tilt();
  return stats;
}

void expectTracksAndCalibrates(const RunStatistics& s) {
  EXPECT_LT(s.position_rms_m, 0.01);  // below the measurement noise: the IMU smooths it
  EXPECT_LT(s.velocity_rms_mps, 0.02);
  EXPECT_LT(s.rotation_rms_rad, 0.002);
  EXPECT_LT((s.final_bias.gyro_radps - kTrueBias.gyro_radps).norm(), 1e-3);
  EXPECT_LT((s.final_bias.accel_mps2 - kTrueBias.accel_mps2).norm(), 0.03);
  // Consistent covariance: the mean NEES of a 3-dof error is 3 for a calibrated estimator.
  EXPECT_GT(s.position_nees, 1.0);
  EXPECT_LT(s.position_nees, 6.0);
}

TEST(OdometrySmoother, FilterTracksThePoseAndCalibratesTheBiases) {
  expectTracksAndCalibrates(runSmoother(2, 30.0));
}

TEST(OdometrySmoother, FixedLagSmootherTracksThePoseAndCalibratesTheBiases) {
  expectTracksAndCalibrates(runSmoother(5, 30.0));
}

TEST(OdometrySmoother, BridgesAGapInTheLidarWithTheImu) {
  // No lidar for 1 s (a registration failure streak): the calibrated IMU carries the pose through.
  const RunStatistics s = runSmoother(5, 30.0, 20.0, 21.0);
  EXPECT_LT(s.position_rms_m, 0.02);
  EXPECT_LT(s.position_nees, 6.0);
}

TEST(OdometrySmoother, EstimatesTheTiltOfAFrameLevelledWrongly) {
  // The poses come in a frame 1.4 deg off level (a levelling that took a horizontal
  // accelerometer bias for a tilt). With the tilt an unknown, the turning rig tells it from the
  // bias; held at zero, the frame's horizontal gravity can only go into the bias (and the
  // attitude), where it does not fit as the rig turns.
  const Eigen::Vector2d frame_tilt_rad(0.015, -0.020);
  const RunStatistics free = runSmoother(5, 30.0, 1e9, 1e9, frame_tilt_rad, 0.03);
  EXPECT_LT((free.tilt_rad - frame_tilt_rad).norm(), 0.1 * kRadPerDeg);
  expectTracksAndCalibrates(free);
  const RunStatistics held = runSmoother(5, 30.0, 1e9, 1e9, frame_tilt_rad, 0.0);
  EXPECT_EQ(held.tilt_rad, Eigen::Vector2d::Zero());
  EXPECT_GT((held.final_bias.accel_mps2 - kTrueBias.accel_mps2).norm(), 0.1);
}

}  // namespace
}  // namespace taiga::backend
