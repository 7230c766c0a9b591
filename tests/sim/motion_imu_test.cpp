// Ground-truth motion and the simulated IMU: exact derivatives, a loop that closes, IMU data that
// integrate back to the trajectory, noise with the configured densities.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/sim/imu.hpp"
#include "taiga/sim/motion.hpp"

namespace taiga::sim {
namespace {

WalkingMotion makeMotion(double duration_s = 60.0, const MotionParams& params = {}) {
  return WalkingMotion(params, duration_s, 1, Terrain(ForestParams{}, 1));
}

/// Central differences of the pose and velocity against the analytic velocity, acceleration and
/// angular rate. h = 1e-5 s keeps the truncation error of the 30 Hz vibration small.
void expectDerivativesMatch(const Motion& motion, double t) {
  SCOPED_TRACE(t);
  const double h = 1e-5;
  const MotionState s = motion.at(t), before = motion.at(t - h), after = motion.at(t + h);
  const Eigen::Vector3d v_num =
      (after.T_world_body.translation() - before.T_world_body.translation()) / (2 * h);
  const Eigen::Vector3d a_num = (after.v_world - before.v_world) / (2 * h);
  const Eigen::Vector3d omega_num =
      after.T_world_body.rotation().minus(before.T_world_body.rotation()) / (2 * h);
  EXPECT_LT((v_num - s.v_world).norm(), 2e-5);
  EXPECT_LT((a_num - s.a_world).norm(), 2e-4);
  EXPECT_LT((omega_num - s.omega_body).norm(), 2e-6);
}

/// Yaw rate about the world's vertical, rad/s.
double worldYawRate(const MotionState& s) {
  return (s.T_world_body.rotation() * s.omega_body).z();
}

Motion makeHarvester(double duration_s, MotionParams params = {}) {
  params.model = MotionModel::kHarvester;
  params.sensor_height_m = 3.8;
  return Motion(params, duration_s, 1, Terrain(ForestParams{}, 1));
}

TEST(WalkingMotion, DerivativesMatchNumericalDifferentiation) {
  const WalkingMotion motion = makeMotion(120.0);
  for (const double t : {0.0, 3.3, 17.9, 41.05}) expectDerivativesMatch(motion, t);
  // Across pauses: while slowing down, standing, and getting going again.
  const auto pauses = motion.standStills();
  ASSERT_GE(pauses.size(), 2u);
  for (const StandStill& p : pauses) {
    for (const double t : {p.start_s - 0.73, p.start_s + 0.2, p.end_s - 0.1, p.end_s + 0.61})
      expectDerivativesMatch(motion, t);
  }
  // Across the fastest turn.
  double t_fastest = 0.0, fastest = 0.0;
  for (double t = 0.0; t < 120.0; t += 0.01) {
    const double rate = std::abs(worldYawRate(motion.at(t)));
    if (rate > fastest) fastest = rate, t_fastest = t;
  }
  for (const double dt : {-0.5, -0.1, 0.0, 0.07, 0.4}) expectDerivativesMatch(motion, t_fastest + dt);
}

TEST(HarvesterMotion, DerivativesMatchNumericalDifferentiation) {
  const Motion motion = makeHarvester(200.0);
  for (const double t : {0.0, 2.9, 4.1, 7.77}) expectDerivativesMatch(motion, t);
  for (const StandStill& stop : motion.standStills()) {
    // Ramps of the drives and (within tree handling) the vibration bursts.
    for (double t = stop.start_s - 1.5; t < stop.end_s + 1.5; t += 0.37) expectDerivativesMatch(motion, t);
  }
}

TEST(WalkingMotion, PausesStopTheWalkForTheirDuration) {
  MotionParams params;
  const WalkingMotion motion = makeMotion(300.0, params);
  const auto pauses = motion.standStills();
  ASSERT_GE(pauses.size(), 5u);  // one every ~30 s of walking
  for (const StandStill& p : pauses) {
    SCOPED_TRACE(p.start_s);
    EXPECT_GE(p.end_s - p.start_s, params.pause_min_s);
    EXPECT_LE(p.end_s - p.start_s, params.pause_max_s);
    // Standing: only the stick's sway moves the sensor (a few cm), walking would cover metres.
    const Eigen::Vector3d p0 = motion.at(p.start_s).T_world_body.translation();
    for (double t = p.start_s; t <= p.end_s; t += 0.05) {
      EXPECT_LT((motion.at(t).T_world_body.translation() - p0).head<2>().norm(), 0.06);
    }
    // Slowing down before: at full speed 1.5 s earlier, about half speed at mid-ramp.
    EXPECT_GT(motion.at(p.start_s - params.pause_ramp_s - 0.3).v_world.head<2>().norm(), 0.6);
    EXPECT_GT((motion.at(p.start_s - params.pause_ramp_s).T_world_body.translation() - p0).norm(),
              0.3);
  }
  // The same walk without pauses is at its start again sooner.
  params.pause_interval_s = 0.0;
  EXPECT_TRUE(makeMotion(300.0, params).standStills().empty());
}

TEST(WalkingMotion, FastTurnsReachAboutNinetyDegreesPerSecond) {
  auto maxYawRate = [](const Motion& motion, double duration_s) {
    double fastest = 0.0;
    for (double t = 0.0; t < duration_s; t += 0.005)
      fastest = std::max(fastest, std::abs(worldYawRate(motion.at(t))));
    return fastest * kDegPerRad;
  };
  MotionParams params;
  const double with_turns = maxYawRate(makeMotion(300.0, params), 300.0);
  EXPECT_GT(with_turns, 80.0);
  EXPECT_LT(with_turns, 95.0);
  params.fast_turn_interval_s = 0.0;
  const double without = maxYawRate(makeMotion(300.0, params), 300.0);
  EXPECT_LT(without, 65.0);  // the look-around swings alone
  EXPECT_GT(without, 20.0);
}

TEST(WalkingMotion, SameSeedSameMotion) {
  const WalkingMotion a = makeMotion(100.0), b = makeMotion(100.0);
  const WalkingMotion other(MotionParams{}, 100.0, 2, Terrain(ForestParams{}, 1));
  const Motion h1 = makeHarvester(100.0), h2 = makeHarvester(100.0);
  bool differs = false;
  for (double t = 0.0; t < 100.0; t += 0.731) {
    EXPECT_EQ(a.at(t).T_world_body.matrix(), b.at(t).T_world_body.matrix());
    EXPECT_EQ(a.at(t).a_world, b.at(t).a_world);
    EXPECT_EQ(h1.at(t).T_world_body.matrix(), h2.at(t).T_world_body.matrix());
    EXPECT_EQ(h1.at(t).omega_body, h2.at(t).omega_body);
    differs |= (a.at(t).T_world_body.translation() - other.at(t).T_world_body.translation()).norm() > 1.0;
  }
  EXPECT_TRUE(differs);
}

TEST(WalkingMotion, CloverleafReturnsThroughTheStartAreaSeveralTimes) {
  MotionParams params;
  params.loop_lobes = 4;
  params.max_loop_length_m = 600.0;
  const WalkingMotion motion = makeMotion(900.0, params);  // the cloverleaf twice
  const Eigen::Vector2d start = motion.at(0.0).T_world_body.translation().head<2>();
  // Count the passes through the start area and where each lobe reaches out to.
  int passes = 0;
  bool inside = true;
  std::vector<Eigen::Vector2d> tips;
  Eigen::Vector2d farthest = start;
  double path_m = 0.0;
  Eigen::Vector2d prev = start;
  for (double t = 0.0; t < motion.loopPeriod_s(); t += 0.1) {
    const Eigen::Vector2d p = motion.at(t).T_world_body.translation().head<2>();
    path_m += (p - prev).norm();
    prev = p;
    const bool near = (p - start).norm() < 6.0;
    if (near && !inside) {
      ++passes;
      tips.push_back(farthest);
      farthest = start;
    }
    if (!near && (p - start).norm() > (farthest - start).norm()) farthest = p;
    inside = near;
  }
  EXPECT_NEAR(path_m, 600.0, 40.0);
  EXPECT_GE(passes, 4);  // back through the start after every lobe
  ASSERT_GE(tips.size(), 4u);
  // Four lobes in four directions, of different sizes.
  double min_reach = 1e9, max_reach = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const double reach = (tips[i] - start).norm();
    min_reach = std::min(min_reach, reach), max_reach = std::max(max_reach, reach);
    for (std::size_t j = 0; j < i; ++j) {
      const double cos_angle = (tips[i] - start).normalized().dot((tips[j] - start).normalized());
      EXPECT_LT(cos_angle, 0.5) << i << " " << j;
    }
  }
  EXPECT_GT(min_reach, 30.0);
  EXPECT_GT(max_reach, 1.2 * min_reach);
  // Back at the start after the first round, and again after the second.
  EXPECT_LT((motion.at(motion.loopPeriod_s()).T_world_body.translation().head<2>() - start).norm(),
            0.15);
  // Nearly constant walking speed along the lobes (the arc-length reparametrization).
  double speed_min = 1e9, speed_max = 0.0;
  for (double t = 1.0; t < 60.0; t += 0.05) {
    bool paused = false;
    for (const StandStill& p : motion.standStills())
      paused |= t > p.start_s - params.pause_ramp_s - 0.5 && t < p.end_s + params.pause_ramp_s + 0.5;
    if (paused) continue;
    const double v = motion.at(t).v_world.head<2>().norm();
    speed_min = std::min(speed_min, v), speed_max = std::max(speed_max, v);
  }
  // 1.35 m/s +- 25 %, +- 0.17 m/s of the stick's sway
  EXPECT_GT(speed_min, 0.75);
  EXPECT_LT(speed_max, 1.95);
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
