// The gyro's noise density measured against registered poses, on synthetic motion with a known
// answer: a body that sways about all axes, a 200 Hz gyro with white noise of a known density (and
// optionally scale and axis errors), and poses at 10 Hz with a registration's rotation noise.
#include "taiga/calib/gyro_noise.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "taiga/core/errors.hpp"

namespace taiga::calib {
namespace {

using Eigen::Vector3d;

// theta(t) = amplitude .* sin(rate .* t): the attitude Exp(theta(t)), a handheld's sway and turns.
const Vector3d kHandheld(0.3, 0.25, 0.8), kRate(1.9, 1.3, 0.4);

Vector3d theta(const Vector3d& amplitude, double t) {
  return amplitude.cwiseProduct((kRate * t).array().sin().matrix());
}

Vector3d omegaBody(const Vector3d& amplitude, double t) {
  const Vector3d theta_dot =
      amplitude.cwiseProduct(kRate).cwiseProduct((kRate * t).array().cos().matrix());
  return lie::SO3::rightJacobian(theta(amplitude, t)) * theta_dot;
}

struct Rig {
  double density = 2.5e-4;                          ///< rad/s/sqrt(Hz)
  double registration_sigma = 1e-4;                 ///< rad per axis
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();  ///< scale and axis errors
  double duration_s = 30.0;
  Vector3d amplitude = kHandheld;
  double gyro_late_s = 0.0;  ///< the gyro's stamps are this late against the poses'
};

GyroNoiseInput simulate(const Rig& rig, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  auto noise3 = [&](double sigma) -> Vector3d {
    return Vector3d(normal(rng), normal(rng), normal(rng)) * sigma;
  };
  constexpr double kRate_hz = 200.0;
  const double reading_sigma = rig.density * std::sqrt(kRate_hz);
  GyroNoiseInput in;
  const Vector3d bias(1e-3, -2e-3, 5e-4);
  in.bias_radps = bias;
  for (double t = 0.0; t <= rig.duration_s + 1.0; t += 1.0 / kRate_hz)
    in.gyro.push_back(
        {t + rig.gyro_late_s, rig.M * omegaBody(rig.amplitude, t) + bias + noise3(reading_sigma)});
  in.chains.emplace_back();
  for (double t = 0.5; t < rig.duration_s; t += 0.1) {
    if (std::fmod(t, 9.0) < 0.1) in.chains.emplace_back();  // a scan not registered now and then
    const lie::SO3 R =
        lie::SO3::Exp(theta(rig.amplitude, t)) * lie::SO3::Exp(noise3(rig.registration_sigma));
    in.chains.back().push_back({t, lie::SE3(R, Vector3d::Zero())});
  }
  return in;
}

TEST(GyroNoise, MeasuresTheDensityBesideTheRegistrationsNoise) {
  for (double density : {2.5e-4, 7.5e-4})
    for (unsigned seed : {1u, 2u}) {
      const GyroNoiseEstimate e = estimateGyroNoise(simulate({.density = density}, seed));
      EXPECT_NEAR(e.density_radps_sqrthz, density, 0.15 * density) << "seed " << seed;
      EXPECT_GT(e.density_sigma, 0.0);
      EXPECT_LT(e.density_sigma, density / 3.0);
      EXPECT_NEAR(e.registration_sigma_rad, 1e-4, 0.5e-4);
      EXPECT_GE(e.lags.size(), 8u);
    }
}

TEST(GyroNoise, ScaleAxisAndTimeErrorsAreNotTakenForNoise) {
  // 1 % scale errors and 0.6 deg misalignments: 4 mrad/s in this sway, 16 times the noise; and
  // 1.5 ms of time offset left over. Left in, they would read as several times the density.
  Eigen::Matrix3d M;
  M << 1.01, 0.01, -0.004, 0.006, 0.99, 0.01, -0.01, 0.003, 1.012;
  for (unsigned seed : {1u, 2u}) {
    const GyroNoiseEstimate e =
        estimateGyroNoise(simulate({.density = 2.5e-4, .M = M, .gyro_late_s = 0.0015}, seed));
    EXPECT_NEAR(e.density_radps_sqrthz, 2.5e-4, 0.15 * 2.5e-4) << "seed " << seed;
    EXPECT_LT((e.rate_error_matrix - (M - Eigen::Matrix3d::Identity())).norm(), 2e-3)
        << e.rate_error_matrix;
    // The offset left over is D's diagonal, D = -dt I (its other terms trade with A's in a sway).
    EXPECT_NEAR(-e.rate_change_matrix_s.trace() / 3.0, 0.0015, 0.0003) << e.rate_change_matrix_s;
  }
}

TEST(GyroNoise, AMachineThatOnlySlewsStillGivesTheDensity) {
  // Turning about z only: the rate error about x and y is not observable and stays zero.
  const GyroNoiseEstimate e =
      estimateGyroNoise(simulate({.density = 2.5e-4, .amplitude = Vector3d(0.0, 0.0, 2.0)}, 6));
  EXPECT_NEAR(e.density_radps_sqrthz, 2.5e-4, 0.15 * 2.5e-4);
  EXPECT_LT(e.rate_error_matrix.leftCols(2).cwiseAbs().maxCoeff(), 1e-3) << e.rate_error_matrix;
}

TEST(GyroNoise, JudgesTheConfiguredDensity) {
  const GyroNoiseEstimate e = estimateGyroNoise(simulate({.density = 7.5e-4}, 3));
  EXPECT_EQ(judgeGyroNoise(e, 7.5e-4).kind, NoiseVerdict::Kind::kConsistent);
  EXPECT_EQ(judgeGyroNoise(e, 6e-4).kind, NoiseVerdict::Kind::kConsistent);
  const NoiseVerdict under = judgeGyroNoise(e, 2.5e-4);  // a datasheet 3x optimistic
  EXPECT_EQ(under.kind, NoiseVerdict::Kind::kUnderstated);
  EXPECT_NEAR(under.suggested, 7.5e-4, 0.25 * 7.5e-4);
  EXPECT_GE(under.suggested, e.density_radps_sqrthz);  // rounded up
  EXPECT_NE(under.text.find("gyro_noise_density"), std::string::npos);
  EXPECT_EQ(judgeGyroNoise(e, 3e-3).kind, NoiseVerdict::Kind::kOverstated);
}

TEST(GyroNoise, UndeterminedWhenTheRegistrationsDrownIt) {
  // Registrations 50x noisier than the gyro's walk over the longest lag: nothing to measure.
  const GyroNoiseEstimate e =
      estimateGyroNoise(simulate({.density = 2.5e-4, .registration_sigma = 2e-2}, 4));
  EXPECT_EQ(judgeGyroNoise(e, 2.5e-4).kind, NoiseVerdict::Kind::kUndetermined);
}

TEST(GyroNoise, TooFewScansInARowAreAnError) {
  GyroNoiseInput in = simulate({.duration_s = 2.0}, 5);
  EXPECT_THROW(estimateGyroNoise(in), InputError);
  in.gyro.clear();
  EXPECT_THROW(estimateGyroNoise(in), InputError);
}

}  // namespace
}  // namespace taiga::calib
