// The four post-fit methods on synthetic loops with a known T_enu_world (yaw 37 deg, hundreds of
// metres of offset): each recovers the transform within bounds derived from the noise, reports
// sigmas consistent with its errors, and the robust method survives multipath that breaks the
// closed-form fit.
//
// Noise-derived bounds: 300 fixes, sigma 0.5 m horizontally and 1 m vertically, positions spread
// about r = 35 m around their centroid: yaw sigma ~ 0.5 / (sqrt(300) 35) = 0.05 deg, horizontal
// offset sigma ~ 0.5 / sqrt(300) = 0.03 m (plus the yaw's lever from the centroid to the world
// origin, ~ 35 m x 0.0008 = 0.03 m), height sigma ~ 1 / sqrt(300) = 0.06 m. The bounds below are
// 4-5x those.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "synthetic_fixes.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/georef/fit.hpp"
#include "taiga/georef/orientation.hpp"

namespace taiga::georef {
namespace {

using test::deg;

struct Errors {
  Eigen::Vector3d translation_m;    ///< estimated - true t, ENU
  Eigen::Vector3d rotation_rad;     ///< Log(R_est R_true^T): about east, north, up
};

Errors errorsOf(const GeorefFit& fit, const lie::SE3& truth) {
  return {fit.T_enu_world.translation() - truth.translation(),
          (fit.T_enu_world.rotation() * truth.rotation().inverse()).Log()};
}

/// Every DoF's error within k reported sigmas: the reported uncertainty means something.
void expectErrorsWithinSigmas(const Errors& e, const GeorefFit& fit, double k) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(e.translation_m[i]), k * fit.sigma[i]) << "translation axis " << i;
  }
  for (int i = 0; i < 3; ++i) {
    if (fit.method == GeorefMethod::kRobust && i < 2) continue;  // roll, pitch assumed, not fitted
    EXPECT_LT(std::abs(e.rotation_rad[i]), k * fit.sigma[3 + i]) << "rotation axis " << i;
  }
}

/// The synthetic noise is white: no inflation for correlated errors.
const FitOptions kWhite{.error_correlation_time_s = 0.0};

const lie::SE3 kTiltedTruth(lie::SO3::fromRollPitchYaw(deg(0.8), deg(-0.5), deg(37.0)),
                            Eigen::Vector3d(312.5, -457.25, 23.1));
const lie::SE3 kLevelTruth(lie::SO3::fromRollPitchYaw(0.0, 0.0, deg(37.0)),
                           Eigen::Vector3d(312.5, -457.25, 23.1));

TEST(GeorefFit, MethodNamesRoundTripAndUnknownNamesAreInputErrors) {
  for (const GeorefMethod m :
       {GeorefMethod::kClosed, GeorefMethod::kPf3, GeorefMethod::kPf6, GeorefMethod::kRobust})
    EXPECT_EQ(parseMethod(methodName(m)), m);
  EXPECT_THROW(parseMethod("icp"), InputError);
}

TEST(GeorefFit, ClosedRecoversATiltedTransformFromNoisyFixes) {
  const auto fixes = test::synthesizeFixes(test::loopWalk(), kTiltedTruth, {});
  const GeorefFit fit = fitClosed(fixes.pairs, kWhite);
  const Errors e = errorsOf(fit, kTiltedTruth);
  EXPECT_LT(e.translation_m.head<2>().norm(), 0.2);
  EXPECT_LT(std::abs(e.translation_m.z()), 0.35);
  EXPECT_LT(std::abs(e.rotation_rad.z()), deg(0.25));
  // Roll and pitch from the heights across the loop: 1 m / (sqrt(300) 35 m) = 0.1 deg 1-sigma.
  EXPECT_LT(e.rotation_rad.head<2>().norm(), deg(0.5));
  expectErrorsWithinSigmas(e, fit, 4.0);
  EXPECT_EQ(fit.inliers, fixes.pairs.size());
  // Residual RMS estimates the noise: sqrt(0.5^2 + 0.5^2 + 1^2) = 1.22 m.
  EXPECT_NEAR(fit.residual_rms_m, 1.22, 0.15);
}

TEST(GeorefFit, Pf3WeighsTheBetterHorizontalFixesAndRecoversTheTransform) {
  const auto fixes = test::synthesizeFixes(test::loopWalk(), kTiltedTruth, {});
  const GeorefFit pf3 = fitPf3(fixes.pairs, kWhite);
  EXPECT_TRUE(pf3.converged);
  const Errors e = errorsOf(pf3, kTiltedTruth);
  EXPECT_LT(e.translation_m.head<2>().norm(), 0.2);
  EXPECT_LT(std::abs(e.rotation_rad.z()), deg(0.25));
  expectErrorsWithinSigmas(e, pf3, 4.0);
  // Weighting trusts the horizontal twice as much as the vertical: pf3's reported roll/pitch
  // sigma is below the unweighted closed fit's (whose variance factor mixes in the bad heights).
  const GeorefFit closed = fitClosed(fixes.pairs, kWhite);
  EXPECT_LT(pf3.sigma[5], closed.sigma[5]);
}

TEST(GeorefFit, Pf3FollowsTheCovarianceOfEachFix) {
  // Half the fixes 10x worse: pf3 down-weights them, the unweighted fit does not.
  auto fixes = test::synthesizeFixes(test::loopWalk(), kLevelTruth, {});
  std::mt19937_64 random(11);
  std::normal_distribution<double> gauss(0.0, 5.0);
  for (std::size_t i = 0; i < fixes.pairs.size(); i += 2) {
    fixes.pairs[i].fix.p_enu += Eigen::Vector3d(gauss(random), gauss(random), 2.0 * gauss(random));
    fixes.pairs[i].fix.covariance_enu_m2 = Eigen::Vector3d(25.25, 25.25, 101.0).asDiagonal();
  }
  const Errors pf3 = errorsOf(fitPf3(fixes.pairs, kWhite), kLevelTruth);
  const Errors closed = errorsOf(fitClosed(fixes.pairs, kWhite), kLevelTruth);
  EXPECT_LT(pf3.translation_m.head<2>().norm(), 0.25);
  EXPECT_LT(pf3.translation_m.norm(), closed.translation_m.norm());
  EXPECT_LT(pf3.rotation_rad.norm(), closed.rotation_rad.norm());
}

std::vector<std::optional<lie::SO3>> measuredOrientations(const test::SyntheticFixes& fixes,
                                                          const lie::SE3& truth,
                                                          double tilt_sigma_rad,
                                                          double heading_sigma_rad) {
  std::mt19937_64 random(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<std::optional<lie::SO3>> R_enu_body;
  for (const AssociatedFix& pair : fixes.pairs) {
    const Eigen::Vector3d error(tilt_sigma_rad * gauss(random), tilt_sigma_rad * gauss(random),
                                heading_sigma_rad * gauss(random));
    R_enu_body.emplace_back(lie::SO3::Exp(error) * truth.rotation() * pair.T_world_body.rotation());
  }
  return R_enu_body;
}

TEST(GeorefFit, Pf6UsesTheImuOrientationForRollAndPitch) {
  const auto fixes = test::synthesizeFixes(test::loopWalk(), kTiltedTruth, {});
  FitOptions options = kWhite;
  options.orientation_tilt_sigma_rad = deg(0.5);
  options.orientation_heading_sigma_rad = deg(2.0);
  const auto orientations = measuredOrientations(fixes, kTiltedTruth, deg(0.5), deg(2.0));
  const GeorefFit pf6 = fitPf6(fixes.pairs, orientations, options);
  EXPECT_TRUE(pf6.converged);
  const Errors e = errorsOf(pf6, kTiltedTruth);
  EXPECT_LT(e.translation_m.head<2>().norm(), 0.2);
  EXPECT_LT(std::abs(e.translation_m.z()), 0.35);
  // 300 orientations of 0.5 deg: 0.03 deg 1-sigma in roll and pitch, better than the heights
  // alone (closed: about 0.1 deg 1-sigma here).
  EXPECT_LT(e.rotation_rad.head<2>().norm(), deg(0.15));
  EXPECT_LT(std::abs(e.rotation_rad.z()), deg(0.25));
  expectErrorsWithinSigmas(e, pf6, 4.0);
  const GeorefFit closed = fitClosed(fixes.pairs, kWhite);
  EXPECT_GT(closed.sigma[3], 2.5 * pf6.sigma[3]);
  EXPECT_GT(closed.sigma[4], 2.5 * pf6.sigma[4]);
}

TEST(GeorefFit, Pf6WithoutOrientationIsAnErrorNotASilentFallback) {
  const auto fixes = test::synthesizeFixes(test::loopWalk(), kTiltedTruth, {});
  const std::vector<std::optional<lie::SO3>> none(fixes.pairs.size());
  try {
    fitPf6(fixes.pairs, none, kWhite);
    FAIL() << "pf6 without orientation did not throw";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("0 of 300 associated fixes have an absolute IMU orientation"));
  }
}

TEST(GeorefFit, Pf6SkipsFixesWithoutOrientationAndCountsThem) {
  const auto fixes = test::synthesizeFixes(test::loopWalk(), kTiltedTruth, {});
  auto orientations = measuredOrientations(fixes, kTiltedTruth, deg(0.5), deg(2.0));
  for (std::size_t i = 0; i < orientations.size(); i += 3) orientations[i].reset();
  const GeorefFit pf6 = fitPf6(fixes.pairs, orientations, kWhite);
  EXPECT_EQ(pf6.without_orientation, (orientations.size() + 2) / 3);
  EXPECT_EQ(pf6.inliers, orientations.size() - pf6.without_orientation);
  EXPECT_LT(errorsOf(pf6, kTiltedTruth).translation_m.head<2>().norm(), 0.25);
}

TEST(GeorefFit, RobustRecoversYawOffsetAndHeightOfALevelMap) {
  const auto fixes = test::synthesizeFixes(test::loopWalk(), kLevelTruth, {});
  const GeorefFit fit = fitRobust(fixes.pairs, kWhite);
  EXPECT_TRUE(fit.converged);
  const Errors e = errorsOf(fit, kLevelTruth);
  EXPECT_LT(e.translation_m.head<2>().norm(), 0.2);
  EXPECT_LT(std::abs(e.translation_m.z()), 0.3);
  EXPECT_LT(std::abs(e.rotation_rad.z()), deg(0.25));
  EXPECT_EQ(e.rotation_rad.head<2>().norm(), 0.0);  // roll and pitch are exactly zero
  expectErrorsWithinSigmas(e, fit, 4.0);
  // Gaussian noise: (almost) nothing is an outlier at 4 robust sigmas.
  EXPECT_LE(fit.outliers, 3u);
  // The reported sigmas are close to the noise-derived ones (header comment), not just large.
  EXPECT_GT(fit.sigma[0], 0.01);
  EXPECT_LT(fit.sigma[0], 0.1);
  EXPECT_GT(fit.sigma[5], deg(0.02));
  EXPECT_LT(fit.sigma[5], deg(0.15));
  EXPECT_NEAR(fit.sigma[2], 1.0 / std::sqrt(299.0), 0.02);
}

TEST(GeorefFit, MultipathBreaksTheClosedFitButNotTheRobustOne) {
  test::NoiseModel noise;
  noise.multipath_share = 0.04;  // bursts of 3 fixes 23 m off: about 11 % of the fixes
  const auto fixes = test::synthesizeFixes(test::loopWalk(), kLevelTruth, noise);
  ASSERT_GT(fixes.multipath, 20u);

  const Errors closed = errorsOf(fitClosed(fixes.pairs, kWhite), kLevelTruth);
  const Errors pf3 = errorsOf(fitPf3(fixes.pairs, kWhite), kLevelTruth);
  // Both least-squares fits are pulled by the mean jump, several metres times the share.
  EXPECT_GT(closed.translation_m.head<2>().norm(), 1.0);
  EXPECT_GT(pf3.translation_m.head<2>().norm(), 1.0);

  const GeorefFit robust = fitRobust(fixes.pairs, kWhite);
  const Errors e = errorsOf(robust, kLevelTruth);
  EXPECT_LT(e.translation_m.head<2>().norm(), 0.2);
  EXPECT_LT(std::abs(e.translation_m.z()), 0.35);
  EXPECT_LT(std::abs(e.rotation_rad.z()), deg(0.25));
  // Every multipath fix is rejected, and few good ones with them.
  std::size_t caught = 0;
  for (std::size_t i = 0; i < fixes.pairs.size(); ++i)
    caught += fixes.is_multipath[i] && !robust.inlier[i] ? 1 : 0;
  EXPECT_EQ(caught, fixes.multipath);
  EXPECT_LE(robust.outliers, fixes.multipath + 3);
  EXPECT_LT(robust.horizontal_rms_m, 1.0);
}

TEST(GeorefFit, TooFewFixesOrAStraightLineAreInputErrors) {
  auto fixes = test::synthesizeFixes(test::loopWalk(), kLevelTruth, {});
  std::vector<AssociatedFix> two(fixes.pairs.begin(), fixes.pairs.begin() + 2);
  EXPECT_THROW(fitRobust(two, kWhite), InputError);
  EXPECT_THROW(fitClosed(two, kWhite), InputError);
  // A straight level walk: heading is determined horizontally (robust), roll about the line is
  // not (closed, pf3).
  std::vector<AssociatedFix> line;
  for (int i = 0; i < 30; ++i) {
    AssociatedFix pair;
    pair.fix.t_s = i;
    pair.p_world = Eigen::Vector3d(1.2 * i, 0.0, 0.0);
    pair.T_world_body = lie::SE3(lie::SO3(), pair.p_world);
    pair.fix.p_enu = kLevelTruth * pair.p_world;
    line.push_back(pair);
  }
  EXPECT_THROW(fitClosed(line, kWhite), InputError);
  EXPECT_THROW(fitPf3(line, kWhite), InputError);
  const GeorefFit robust = fitRobust(line, kWhite);
  EXPECT_LT(std::abs(errorsOf(robust, kLevelTruth).rotation_rad.z()), 1e-9);
  // Fixes all at one time: the error model cannot order them.
  for (AssociatedFix& pair : line) pair.fix.t_s = 5.0;
  EXPECT_THROW(fitRobust(line, kWhite), InputError);
}

TEST(GeorefFit, SameInputGivesIdenticalOutput) {
  test::NoiseModel noise;
  noise.multipath_share = 0.04;
  const auto fixes = test::synthesizeFixes(test::loopWalk(), kLevelTruth, noise);
  for (auto method : {fitClosed, fitPf3, fitRobust}) {
    const GeorefFit a = method(fixes.pairs, kWhite), b = method(fixes.pairs, kWhite);
    EXPECT_EQ(a.T_enu_world.matrix(), b.T_enu_world.matrix());
    EXPECT_EQ(a.sigma, b.sigma);
  }
}

/// Errors of a method over many synthetic walks: RMS per DoF (east, north, up, yaw) and how often
/// each lay within 1 and 2 reported sigmas.
struct Spread {
  Eigen::Vector4d rms = Eigen::Vector4d::Zero();
  Eigen::Vector4d rms_sigma = Eigen::Vector4d::Zero();
  double within_1_sigma = 0.0, within_2_sigma = 0.0;
  int distrusted = 0;  ///< robust: runs whose error model believed less than every sigma swing
};

Spread spreadOver(int runs, test::NoiseModel noise, const FitOptions& options,
                  GeorefFit (*method)(const std::vector<AssociatedFix>&, const FitOptions&)) {
  const Trajectory walk = test::loopWalk();
  Spread spread;
  int within_1 = 0, within_2 = 0;
  for (int run = 0; run < runs; ++run) {
    noise.seed = 100 + run;
    const auto fixes = test::synthesizeFixes(walk, kLevelTruth, noise);
    const GeorefFit fit = method(fixes.pairs, options);
    const Errors e = errorsOf(fit, kLevelTruth);
    const Eigen::Vector4d error(e.translation_m.x(), e.translation_m.y(), e.translation_m.z(),
                                e.rotation_rad.z());
    const Eigen::Vector4d sigma(fit.sigma[0], fit.sigma[1], fit.sigma[2], fit.sigma[5]);
    spread.rms += error.cwiseProduct(error);
    spread.rms_sigma += sigma.cwiseProduct(sigma);
    for (int k = 0; k < 4; ++k) {
      within_1 += std::abs(error[k]) <= sigma[k] ? 1 : 0;
      within_2 += std::abs(error[k]) <= 2.0 * sigma[k] ? 1 : 0;
    }
    spread.distrusted += fit.error_model && fit.error_model->sigma_trust < 1.0 ? 1 : 0;
  }
  spread.rms = (spread.rms / runs).cwiseSqrt();
  spread.rms_sigma = (spread.rms_sigma / runs).cwiseSqrt();
  spread.within_1_sigma = within_1 / (4.0 * runs);
  spread.within_2_sigma = within_2 / (4.0 * runs);
  return spread;
}

/// Gauss-Markov GNSS errors (tau 30 s) whose sigma swings by +-60 % from fix to fix (canopy).
test::NoiseModel canopyNoise() {
  test::NoiseModel noise;
  noise.correlation_time_s = 30.0;
  noise.sigma_swing = 0.6;
  return noise;
}

TEST(GeorefFit, RobustModelsCorrelatedErrorsAndItsSigmasCoverThem) {
  // The errors' size follows the fix's sigma, reported 0.7x too small (the simulator's canopy
  // model), over 40 walks.
  test::NoiseModel noise = canopyNoise();
  noise.reported_sigma_factor = 0.7;
  const FitOptions modelled{.error_correlation_time_s = 30.0};
  const Spread robust = spreadOver(40, noise, modelled, fitRobust);
  // Calibrated: about 68 % within 1 sigma and 95 % within 2 (160 errors: +-7 % is 2 binomial
  // sigmas).
  EXPECT_GT(robust.within_1_sigma, 0.55);
  EXPECT_LT(robust.within_1_sigma, 0.82);
  EXPECT_GT(robust.within_2_sigma, 0.88);
  EXPECT_LT(robust.distrusted, 8);
  // The model pays: the closed-form fit (white noise, its own inflation for correlation) is
  // less accurate in every DoF, and its sigmas do not know it.
  const Spread closed = spreadOver(40, noise, modelled, fitClosed);
  for (int k = 0; k < 4; ++k) {
    EXPECT_LT(robust.rms[k], 0.7 * closed.rms[k]) << k;
    EXPECT_GT(robust.rms_sigma[k], 0.7 * robust.rms[k]) << k;
    EXPECT_LT(robust.rms_sigma[k], 1.4 * robust.rms[k]) << k;
  }
}

TEST(GeorefFit, RobustSigmasStayHonestWhenTheReportedSigmaIsItselfNoisy) {
  // The errors follow the true sigma, but the receiver reports it with a 20 % random error per
  // fix: believing every swing would read the offset from that noise (tried: within 2 sigma
  // 57 %); the fit believes a share of them.
  test::NoiseModel noise = canopyNoise();
  noise.reported_sigma_noise = 0.2;
  const FitOptions modelled{.error_correlation_time_s = 30.0};
  const Spread robust = spreadOver(40, noise, modelled, fitRobust);
  EXPECT_GT(robust.distrusted, 30);
  EXPECT_GT(robust.within_1_sigma, 0.55);
  EXPECT_GT(robust.within_2_sigma, 0.88);
  const Spread closed = spreadOver(40, noise, modelled, fitClosed);
  for (int k = 0; k < 4; ++k) EXPECT_LT(robust.rms[k], 0.7 * closed.rms[k]) << k;
}

TEST(GeorefFit, RobustSigmasStayHonestWhenTheErrorsDoNotFollowTheReportedSigma) {
  // The same, but the errors' size is constant while the reported sigma swings: taking every
  // swing at its word would make the fit far too sure of itself (tried: within 2 sigma 35 %).
  test::NoiseModel noise = canopyNoise();
  noise.errors_follow_sigma = false;
  const Spread robust =
      spreadOver(40, noise, FitOptions{.error_correlation_time_s = 30.0}, fitRobust);
  EXPECT_GT(robust.distrusted, 30);
  EXPECT_GT(robust.within_1_sigma, 0.5);
  EXPECT_GT(robust.within_2_sigma, 0.85);
}

TEST(GeorefOrientation, NedOrientationsAreTurnedIntoEnuAndUnknownOnesAreSkipped) {
  const lie::SO3 R_enu_imu = lie::SO3::fromRollPitchYaw(deg(2.0), deg(-1.0), deg(50.0));
  const lie::SO3 R_ned_imu = R_enu_ned().inverse() * R_enu_imu;
  // NED's north axis is ENU's y, its down is -z.
  EXPECT_LT((R_enu_ned() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_LT((R_enu_ned() * Eigen::Vector3d::UnitZ() + Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  std::vector<ImuSample> imu(3);
  imu[0].t_s = 1.0;
  imu[0].orientation = ImuOrientation{R_ned_imu.quaternion(), OrientationReference::kNed};
  imu[1].t_s = 1.01;
  imu[1].orientation = ImuOrientation{R_enu_imu.quaternion(), OrientationReference::kEnu};
  imu[2].t_s = 1.02;
  imu[2].orientation = ImuOrientation{R_enu_imu.quaternion(), OrientationReference::kUnknown};
  // The IMU turned 90 deg about the body's z: R_enu_body = R_enu_imu R_body_imu^T.
  const lie::SE3 T_body_imu(lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), deg(90.0)),
                            Eigen::Vector3d(0.1, 0, 0));
  const auto samples = absoluteOrientations(imu, T_body_imu);
  ASSERT_EQ(samples.size(), 2u);
  const lie::SO3 expected = R_enu_imu * T_body_imu.rotation().inverse();
  EXPECT_LT((samples[0].R_enu_body.inverse() * expected).angle(), 1e-12);
  EXPECT_LT((samples[1].R_enu_body.inverse() * expected).angle(), 1e-12);

  const auto at = orientationsAt(samples, {0.5, 1.0, 1.005, 1.5});
  EXPECT_FALSE(at[0]);
  ASSERT_TRUE(at[1] && at[2]);
  EXPECT_LT((*at[2] * expected.inverse()).angle(), 1e-9);
  EXPECT_FALSE(at[3]);
}

}  // namespace
}  // namespace taiga::georef
