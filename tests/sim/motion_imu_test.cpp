// Ground-truth motion and the simulated IMU: exact derivatives, a loop that closes, IMU data that
// integrate back to the trajectory, noise with the configured densities.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "taiga/sim/imu.hpp"
#include "taiga/sim/motion.hpp"

namespace taiga::sim {
namespace {

WalkingMotion makeMotion(double duration_s = 60.0, const MotionParams& params = {}) {
  return WalkingMotion(params, duration_s, 1, Terrain(ForestParams{}, 1));
}

TEST(WalkingMotion, DerivativesMatchNumericalDifferentiation) {
  const WalkingMotion motion = makeMotion();
  const double h = 1e-4;
  for (const double t : {0.0, 3.3, 17.9, 41.05}) {
    SCOPED_TRACE(t);
    const MotionState s = motion.at(t), before = motion.at(t - h), after = motion.at(t + h);
    const Eigen::Vector3d v_num =
        (after.T_world_body.translation() - before.T_world_body.translation()) / (2 * h);
    const Eigen::Vector3d a_num = (after.v_world - before.v_world) / (2 * h);
    const Eigen::Vector3d omega_num =
        after.T_world_body.rotation().minus(before.T_world_body.rotation()) / (2 * h);
    EXPECT_LT((v_num - s.v_world).norm(), 1e-6);
    EXPECT_LT((a_num - s.a_world).norm(), 1e-5);
    EXPECT_LT((omega_num - s.omega_body).norm(), 1e-6);
  }
}

TEST(WalkingMotion, WalksAtHandheldSpeedAndReturnsToItsStart) {
  const WalkingMotion motion = makeMotion(60.0);
  double speed_sum = 0.0, max_yaw_rate = 0.0;
  int n = 0;
  for (double t = 0.0; t < motion.loopPeriod_s(); t += 0.05, ++n) {
    const MotionState s = motion.at(t);
    speed_sum += s.v_world.head<2>().norm();
    max_yaw_rate = std::max(max_yaw_rate, std::abs(s.omega_body.z()));
  }
  EXPECT_NEAR(speed_sum / n, 1.35, 0.25);
  EXPECT_GT(max_yaw_rate, 0.5);  // the operator turns quickly now and then (rad/s)
  EXPECT_LT(max_yaw_rate, 2.5);
  EXPECT_NEAR(motion.loopPeriod_s(), 0.95 * 60.0, 1e-9);
  // Back at the start after one loop, apart from the gait's sway and bob.
  const Eigen::Vector3d start = motion.at(0.0).T_world_body.translation();
  const Eigen::Vector3d back = motion.at(motion.loopPeriod_s()).T_world_body.translation();
  EXPECT_LT((back - start).norm(), 0.15);
  EXPECT_GT((motion.at(0.5 * motion.loopPeriod_s()).T_world_body.translation() - start).norm(),
            10.0);
}

/// Integrates IMU samples (trapezoidal in the world frame, midpoint rotation update) from the
/// true initial state; returns the largest position error against the truth.
double integrationError(const WalkingMotion& motion, const std::vector<ImuSample>& samples,
                        double gravity, double* max_rotation_error_rad) {
  const Eigen::Vector3d g(0, 0, -gravity);
  MotionState s0 = motion.at(samples.front().t_s);
  lie::SO3 R = s0.T_world_body.rotation();
  Eigen::Vector3d p = s0.T_world_body.translation(), v = s0.v_world;
  double max_error = 0.0;
  *max_rotation_error_rad = 0.0;
  for (std::size_t k = 0; k + 1 < samples.size(); ++k) {
    const double dt = samples[k + 1].t_s - samples[k].t_s;
    const Eigen::Vector3d a0 = R * samples[k].acceleration_imu_mps2 + g;
    const Eigen::Vector3d omega =
        0.5 * (samples[k].angular_velocity_imu_radps + samples[k + 1].angular_velocity_imu_radps);
    R = R * lie::SO3::Exp(omega * dt);
    const Eigen::Vector3d a1 = R * samples[k + 1].acceleration_imu_mps2 + g;
    p += v * dt + (a0 / 3.0 + a1 / 6.0) * dt * dt;
    v += 0.5 * (a0 + a1) * dt;
    const MotionState truth = motion.at(samples[k + 1].t_s);
    max_error = std::max(max_error, (p - truth.T_world_body.translation()).norm());
    *max_rotation_error_rad =
        std::max(*max_rotation_error_rad, R.minus(truth.T_world_body.rotation()).norm());
  }
  return max_error;
}

TEST(ImuSimulator, NoiselessSamplesIntegrateToTheTrueTrajectory) {
  const WalkingMotion motion = makeMotion();
  ImuParams params;
  params.noise = false;
  params.rate_hz = 400.0;
  ImuSimulator imu(params, 1);
  std::vector<ImuSample> samples;
  while (imu.nextTime_s() <= 5.0) samples.push_back(imu.next(motion));
  ASSERT_EQ(samples.size(), 2001u);
  EXPECT_DOUBLE_EQ(samples[1].t_s - samples[0].t_s, 1.0 / 400.0);
  double rotation_error = 0.0;
  const double position_error =
      integrationError(motion, samples, params.gravity_mps2, &rotation_error);
  EXPECT_LT(position_error, 0.005);  // 5 mm after 5 s of walking, from integration error only
  EXPECT_LT(rotation_error, 1e-4);
  // A wrong gravity sign or frame would be off by metres.
  ImuParams wrong = params;
  wrong.gravity_mps2 = 9.71;
  ImuSimulator wrong_imu(wrong, 1);
  std::vector<ImuSample> wrong_samples;
  while (wrong_imu.nextTime_s() <= 5.0) wrong_samples.push_back(wrong_imu.next(motion));
  EXPECT_GT(integrationError(motion, wrong_samples, params.gravity_mps2, &rotation_error), 0.5);
}

double stddev(const std::vector<double>& x) {
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / x.size();
  double s = 0.0;
  for (const double v : x) s += (v - mean) * (v - mean);
  return std::sqrt(s / (x.size() - 1));
}

TEST(ImuSimulator, NoiseMatchesTheConfiguredDensities) {
  const WalkingMotion motion = makeMotion();
  ImuParams params;  // defaults, noise on
  ImuParams exact = params;
  exact.noise = false;
  ImuSimulator noisy(params, 9), truth(exact, 9);
  const std::size_t n = 40000;
  std::vector<double> accel_white, gyro_white, accel_walk, gyro_walk;
  ImuBiases previous = noisy.biases();
  const ImuBiases turn_on = noisy.biases();
  for (std::size_t k = 0; k < n; ++k) {
    const ImuSample a = noisy.next(motion), b = truth.next(motion);
    const ImuBiases& bias = noisy.biases();
    const Eigen::Vector3d accel_noise =
        a.acceleration_imu_mps2 - b.acceleration_imu_mps2 - bias.accel_mps2;
    const Eigen::Vector3d gyro_noise =
        a.angular_velocity_imu_radps - b.angular_velocity_imu_radps - bias.gyro_radps;
    for (int i = 0; i < 3; ++i) {
      accel_white.push_back(accel_noise[i]);
      gyro_white.push_back(gyro_noise[i]);
      if (k > 0) {
        accel_walk.push_back(bias.accel_mps2[i] - previous.accel_mps2[i]);
        gyro_walk.push_back(bias.gyro_radps[i] - previous.gyro_radps[i]);
      }
    }
    previous = bias;
  }
  const double rate = params.rate_hz, dt = 1.0 / rate;
  EXPECT_NEAR(stddev(accel_white), params.accel_noise_density * std::sqrt(rate),
              0.02 * params.accel_noise_density * std::sqrt(rate));
  EXPECT_NEAR(stddev(gyro_white), params.gyro_noise_density * std::sqrt(rate),
              0.02 * params.gyro_noise_density * std::sqrt(rate));
  EXPECT_NEAR(stddev(accel_walk), params.accel_bias_random_walk * std::sqrt(dt),
              0.02 * params.accel_bias_random_walk * std::sqrt(dt));
  EXPECT_NEAR(stddev(gyro_walk), params.gyro_bias_random_walk * std::sqrt(dt),
              0.02 * params.gyro_bias_random_walk * std::sqrt(dt));
  // Turn-on biases are drawn, non-zero and of the configured size.
  EXPECT_GT(turn_on.accel_mps2.norm(), 0.0);
  EXPECT_LT(turn_on.accel_mps2.cwiseAbs().maxCoeff(), 5.0 * params.accel_turn_on_bias);
  EXPECT_LT(turn_on.gyro_radps.cwiseAbs().maxCoeff(), 5.0 * params.gyro_turn_on_bias);
}

}  // namespace
}  // namespace taiga::sim
