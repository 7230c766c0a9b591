// GNSS fused in the mapping graph (issue 9 item 2): a synthetic 200 m rectangular walk whose
// odometry drifts in heading and scale, with fixes from a known T_enu_map. The fused graph must
// find T_enu_map within the noise, pull the drifted map back onto the truth, shrug off a
// multipath burst (and only because of its robust kernel), wait until the heading is observable,
// and give the same answer whether it runs inline or on the mapping thread.
#include "taiga/mapping/gnss_fusion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/georef/fit.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/mapper.hpp"

namespace taiga::mapping {
namespace {

constexpr double kStartS = 1000.0;  // keyframe k at kStartS + k, 1 m apart (1 m/s)
const geo::Geodetic kOrigin{61.0, 24.5, 120.0};
// Where the map lies in ENU at kOrigin: heading 35 deg, origin 120 m east, 45 m south, 3 m up.
const lie::SE3 kTrueEnuWorld(lie::SO3::fromRollPitchYaw(0, 0, 35.0 * kRadPerDeg), {120, -45, 3});

// 200 keyframes 1 m apart: 140 m straight, a 90 deg turn to the left, 60 m on.
std::vector<lie::SE3> trueRectangle() {
  std::vector<lie::SE3> poses;
  lie::SE3 T_world_body;
  for (int k = 0; k < 200; ++k) {
    poses.push_back(T_world_body);
    const bool corner = k == 139;
    T_world_body =
        T_world_body *
        lie::SE3::Exp(
            (lie::Vector6() << 1, 0, 0, 0, 0, corner ? 90.0 * kRadPerDeg : 0.0).finished());
  }
  return poses;
}

// Heading drift 0.02 deg/m (4 deg over the walk) and steps 0.2 % long: 4.7 m off at the end,
// 0.5 m ATE after the best rigid alignment.
std::vector<lie::SE3> driftingOdometry(const std::vector<lie::SE3>& truth) {
  std::vector<lie::SE3> odometry{truth.front()};
  for (std::size_t k = 1; k < truth.size(); ++k) {
    const lie::SE3 step = truth[k - 1].inverse() * truth[k];
    odometry.push_back(odometry.back() * lie::SE3(step.rotation() * lie::SO3::Exp(Eigen::Vector3d(
                                                                        0, 0, 0.02 * kRadPerDeg)),
                                                  step.translation() * 1.002));
  }
  return odometry;
}

struct FixNoise {
  Eigen::Vector3d p_body_antenna_m = Eigen::Vector3d::Zero();  ///< where the fixes are taken
  double sigma_horizontal_m = 0.5;
  double sigma_vertical_m = 0.9;
  std::size_t burst_begin = 0, burst_end = 0;  ///< fixes in [begin, end) jump by burst_m
  Eigen::Vector3d burst_m = Eigen::Vector3d::Zero();
};

// One fix per keyframe interval, half-way (t_k + 0.5 s), at the true antenna position in ENU
// plus white noise, reported with the true sigmas.
std::vector<GnssFix> fixesFor(const std::vector<lie::SE3>& truth, const FixNoise& noise,
                              unsigned seed) {
  const geo::CoordinateConverter converter;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<GnssFix> fixes;
  for (std::size_t k = 0; k + 1 < truth.size(); ++k) {
    const Eigen::Vector3d p_world =
        lie::interpolate(truth[k], truth[k + 1], 0.5) * noise.p_body_antenna_m;
    Eigen::Vector3d p_enu = kTrueEnuWorld * p_world;
    p_enu +=
        Eigen::Vector3d(noise.sigma_horizontal_m * gauss(rng),
                        noise.sigma_horizontal_m * gauss(rng), noise.sigma_vertical_m * gauss(rng));
    const std::size_t i = fixes.size();
    if (i >= noise.burst_begin && i < noise.burst_end) p_enu += noise.burst_m;
    const geo::Geodetic where = converter.fromEnu(kOrigin, p_enu);
    GnssFix fix;
    fix.t_s = kStartS + static_cast<double>(k) + 0.5;
    fix.latitude_deg = where.latitude_deg;
    fix.longitude_deg = where.longitude_deg;
    fix.height_ellipsoid_m = where.height_m;
    fix.covariance_enu_m2 =
        Eigen::Vector3d(std::pow(noise.sigma_horizontal_m, 2),
                        std::pow(noise.sigma_horizontal_m, 2), std::pow(noise.sigma_vertical_m, 2))
            .asDiagonal();
    fix.covariance_type = GnssCovarianceType::kDiagonalKnown;
    fix.status = GnssStatus::kFix;
    fixes.push_back(fix);
  }
  return fixes;
}

MappingConfig fusionConfig() {
  MappingConfig config;
  config.loop_closure = false;
  config.gnss_fusion = true;
  return config;
}

/// The receiver's settings (the georef section): the synthetic noise is white.
GeorefConfig whiteGnss() {
  GeorefConfig gnss;
  gnss.error_correlation_time_s = 0.0;
  return gnss;
}

struct Fused {
  PoseGraph graph;
  GnssFusionReport report;
};

// Keyframes and fixes interleaved by time, as taiga run hands them over, then the final solve.
Fused fuse(const MappingConfig& config, const std::vector<lie::SE3>& odometry,
           const std::vector<GnssFix>& fixes, const GeorefConfig& gnss = whiteGnss()) {
  PoseGraph graph(config);
  GnssFusion fusion(config, gnss);
  std::vector<double> times_s;
  std::size_t next_fix = 0;
  for (std::size_t k = 0; k < odometry.size(); ++k) {
    const double t_s = kStartS + static_cast<double>(k);
    for (; next_fix < fixes.size() && fixes[next_fix].t_s <= t_s; ++next_fix)
      fusion.addFix(fixes[next_fix]);
    graph.addKeyframe(odometry[k]);
    times_s.push_back(t_s);
    if (fusion.afterKeyframe(graph, times_s)) graph.optimize();
  }
  for (; next_fix < fixes.size(); ++next_fix) fusion.addFix(fixes[next_fix]);
  if (fusion.finish(graph)) graph.optimize();
  return {graph, fusion.report(graph)};
}

// The true T_enu_map in the ENU frame the fusion uses: the one at the first fix.
lie::SE3 trueEnuWorldAtFirstFix(const GnssFix& first) {
  const geo::CoordinateConverter converter;
  const geo::Geodetic origin{first.latitude_deg, first.longitude_deg, first.height_ellipsoid_m};
  // Three points fix the rigid map between the two ENU frames (100 m apart: 0.001 deg).
  const Eigen::Vector3d o = converter.toEnu(origin, kOrigin);
  const Eigen::Vector3d ex = converter.toEnu(origin, converter.fromEnu(kOrigin, {100, 0, 0})) - o;
  const Eigen::Vector3d ey = converter.toEnu(origin, converter.fromEnu(kOrigin, {0, 100, 0})) - o;
  Eigen::Matrix3d R;
  R << ex.normalized(), ey.normalized(), ex.normalized().cross(ey.normalized());
  return lie::SE3(lie::SO3::fromMatrix(R), o) * kTrueEnuWorld;
}

double worstPositionError(const std::vector<lie::SE3>& estimate,
                          const std::vector<lie::SE3>& truth) {
  double worst = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k)
    worst = std::max(worst, (estimate[k].translation() - truth[k].translation()).norm());
  return worst;
}

// RMS over the keyframes of T_enu_map * p_world against the truth in ENU.
double georefRms(const Fused& fused, const lie::SE3& T_enu_world_true,
                 const std::vector<lie::SE3>& truth) {
  double sum = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k)
    sum += (*fused.report.T_enu_map * fused.graph.pose(k).translation() -
            T_enu_world_true * truth[k].translation())
               .squaredNorm();
  return std::sqrt(sum / static_cast<double>(truth.size()));
}

// The map's internal accuracy: RMS position error after the best rigid alignment onto the truth
// (the ATE of taiga eval), through the closed-form fit of georef.
double ateAfterAlignment(const std::vector<lie::SE3>& poses, const std::vector<lie::SE3>& truth) {
  std::vector<georef::AssociatedFix> pairs;
  for (std::size_t k = 0; k < truth.size(); ++k)
    pairs.push_back({.fix = {.t_s = static_cast<double>(k), .p_enu = truth[k].translation()},
                     .T_world_body = poses[k],
                     .p_world = poses[k].translation()});
  georef::FitOptions options;
  options.error_correlation_time_s = 0.0;
  return georef::fitClosed(pairs, options).residual_rms_m;
}

double yawDeg(const lie::SE3& T) { return georef::rollPitchYaw(T.rotation()).z() * kDegPerRad; }

TEST(GnssFusion, RecoversTheMapToEnuTransformAndRemovesTheDrift) {
  const std::vector<lie::SE3> truth = trueRectangle();
  const std::vector<lie::SE3> odometry = driftingOdometry(truth);
  const std::vector<GnssFix> fixes = fixesFor(truth, {}, 1);
  const Fused fused = fuse(fusionConfig(), odometry, fixes);

  ASSERT_TRUE(fused.report.T_enu_map.has_value());
  EXPECT_EQ(fused.report.total, fixes.size());
  EXPECT_EQ(fused.report.used, fixes.size());  // every fix lies between two keyframes
  EXPECT_EQ(fused.report.gated + fused.report.outside + fused.report.waiting, 0u);
  const lie::SE3 expected = trueEnuWorldAtFirstFix(fixes.front());
  // The georeferenced map, T_enu_map * T_world_k, against the truth in ENU: 199 fixes of
  // 0.5 m white noise along 200 m pin it to about 0.1 m (measured 0.125 m).
  EXPECT_LT(georefRms(fused, expected, truth), 0.2);
  // T_enu_map itself: the fused map's heading may settle a little away from the first
  // keyframe's (the odometry lets the first metres bend), and T_enu_map turns with it
  // (measured 0.67 deg, 0.2 m); the unfused start fit from the first 10 m is far worse.
  const lie::SE3& estimated = *fused.report.T_enu_map;
  EXPECT_LT(std::abs(yawDeg(estimated.inverse() * expected)), 1.0);
  EXPECT_LT((estimated.translation() - expected.translation()).norm(), 0.4);

  // The map's internal accuracy (ATE after rigid alignment): 0.51 m -> 0.09 m measured.
  const double odometry_ate_m = ateAfterAlignment(odometry, truth);
  const double fused_ate_m = ateAfterAlignment(fused.graph.poses(), truth);
  RecordProperty("georef_rms_m", std::to_string(georefRms(fused, expected, truth)));
  RecordProperty("odometry_ate_m", std::to_string(odometry_ate_m));
  RecordProperty("fused_ate_m", std::to_string(fused_ate_m));
  EXPECT_GT(odometry_ate_m, 0.4);  // the drift is there to remove
  EXPECT_LT(fused_ate_m, 0.3 * odometry_ate_m);
}

// A burst of 12 fixes (12 s) 20 m east, as multipath under a dense canopy patch gives.
FixNoise multipathBurst() {
  FixNoise noise;
  noise.burst_begin = 120;
  noise.burst_end = 132;
  noise.burst_m = {20, 0, 0};
  return noise;
}

TEST(GnssFusion, AMultipathBurstDoesNotPullTheMap) {
  const std::vector<lie::SE3> truth = trueRectangle();
  const std::vector<lie::SE3> odometry = driftingOdometry(truth);
  const Fused clean = fuse(fusionConfig(), odometry, fixesFor(truth, {}, 2));
  const Fused burst = fuse(fusionConfig(), odometry, fixesFor(truth, multipathBurst(), 2));

  // The burst's fixes end up beyond the Huber threshold, and the map moves by less than 0.3 m.
  EXPECT_GE(burst.report.down_weighted, 12u);
  EXPECT_LT(burst.report.down_weighted, 20u);
  const double pulled_m = worstPositionError(burst.graph.poses(), clean.graph.poses());
  RecordProperty("pulled_m", std::to_string(pulled_m));
  RecordProperty("down_weighted", std::to_string(burst.report.down_weighted));
  EXPECT_LT(pulled_m, 0.3);

  // Without the kernel (threshold far away) the same burst drags the map by metres: the test
  // above would notice a broken kernel.
  MappingConfig no_kernel = fusionConfig();
  no_kernel.gnss_huber_sigmas = 1e6;
  const Fused dragged = fuse(no_kernel, odometry, fixesFor(truth, multipathBurst(), 2));
  RecordProperty("dragged_m",
                 std::to_string(worstPositionError(dragged.graph.poses(), clean.graph.poses())));
  EXPECT_GT(worstPositionError(dragged.graph.poses(), clean.graph.poses()), 4.0 * pulled_m);
  EXPECT_GT(worstPositionError(dragged.graph.poses(), clean.graph.poses()), 0.5);
}

TEST(GnssFusion, WaitsUntilTheHeadingIsObservableAndGatesPoorFixes) {
  const std::vector<lie::SE3> truth = trueRectangle();
  const std::vector<lie::SE3> odometry = driftingOdometry(truth);
  std::vector<GnssFix> fixes = fixesFor(truth, {}, 3);
  fixes[0].status = GnssStatus::kNoFix;                            // no fix
  fixes[1].covariance_enu_m2 = Eigen::Matrix3d::Identity() * 100;  // 10 m > 5 m
  const MappingConfig config = fusionConfig();

  // 8 keyframes: 7 m of track, 5 usable fixes: below the 10 m spread, nothing fused yet.
  const std::vector<lie::SE3> start(odometry.begin(), odometry.begin() + 8);
  const Fused early = fuse(config, start, std::vector<GnssFix>(fixes.begin(), fixes.begin() + 7));
  EXPECT_EQ(early.report.gated, 2u);
  EXPECT_EQ(early.report.used, 0u);
  EXPECT_EQ(early.report.waiting, 5u);
  EXPECT_FALSE(early.report.T_enu_map.has_value());
  EXPECT_TRUE(early.graph.gnss().empty());

  // 16 keyframes (15 m): fusion starts, with every fix attached so far.
  const std::vector<lie::SE3> longer(odometry.begin(), odometry.begin() + 16);
  const Fused started =
      fuse(config, longer, std::vector<GnssFix>(fixes.begin(), fixes.begin() + 18));
  EXPECT_TRUE(started.report.T_enu_map.has_value());
  EXPECT_EQ(started.report.used, 13u);    // fixes 2..14 lie between keyframes 0 and 15
  EXPECT_EQ(started.report.outside, 3u);  // fixes 15..17 come after the last keyframe
  EXPECT_EQ(started.graph.gnss().size(), 13u);
}

TEST(GnssFusion, MappingThreadGivesTheInlineResultBitForBit) {
  const test::TempDir dir;
  const std::vector<lie::SE3> truth = trueRectangle();
  const std::vector<lie::SE3> odometry = driftingOdometry(truth);
  const std::vector<GnssFix> fixes = fixesFor(truth, multipathBurst(), 4);
  const MappingConfig config = fusionConfig();
  const GeorefConfig gnss;  // tau 30 s: the weighting path too
  const KeyframeStore store = KeyframeStore::create(dir.path());
  const OdometryConfig odometry_config;

  // The fixes reach the mapper late (after the keyframe that follows them), as they may from a
  // pipelined odometry; the result must depend only on the order of the calls.
  auto run = [&](auto& mapper) {
    std::size_t next_fix = 0;
    for (std::size_t k = 0; k < odometry.size(); ++k) {
      mapper.addKeyframe(k, kStartS + static_cast<double>(k), odometry[k]);
      for (; next_fix < fixes.size() && fixes[next_fix].t_s <= kStartS + k + 0.6; ++next_fix)
        mapper.addGnssFix(fixes[next_fix]);
    }
  };
  Mapper inline_mapper(config, odometry_config, store, verifyLoop, gnss);
  run(inline_mapper);
  inline_mapper.finish();
  std::vector<std::vector<lie::SE3>> threaded_poses;
  for (int repeat = 0; repeat < 2; ++repeat) {
    MappingThread thread(config, odometry_config, store, {.gnss = gnss});
    run(thread);
    threaded_poses.push_back(thread.finish().graph().poses());
    ASSERT_TRUE(thread.finish().gnssReport()->T_enu_map.has_value());
    EXPECT_EQ(thread.finish().gnssReport()->T_enu_map->matrix(),
              inline_mapper.gnssReport()->T_enu_map->matrix());
  }
  const std::vector<lie::SE3>& inline_poses = inline_mapper.graph().poses();
  ASSERT_EQ(inline_mapper.gnssReport()->used, fixes.size());
  for (const auto& poses : threaded_poses) {
    ASSERT_EQ(poses.size(), inline_poses.size());
    for (std::size_t k = 0; k < poses.size(); ++k)
      EXPECT_EQ(poses[k].matrix(), inline_poses[k].matrix()) << "keyframe " << k;
  }
  // Correlation weighting (f = 60 for fixes 1 s apart, tau 30 s) makes the fixes count as about
  // 3 independent ones: the map still improves, a little (ATE 0.51 m -> 0.44 m without the burst).
  EXPECT_LT(ateAfterAlignment(inline_poses, truth), 0.95 * ateAfterAlignment(odometry, truth));
}

TEST(GnssFusion, OffByDefault) {
  const test::TempDir dir;
  const KeyframeStore store = KeyframeStore::create(dir.path());
  MappingConfig config;
  config.loop_closure = false;
  EXPECT_FALSE(config.gnss_fusion);
  Mapper mapper(config, OdometryConfig{}, store);
  const std::vector<lie::SE3> truth = trueRectangle();
  const std::vector<GnssFix> fixes = fixesFor(truth, {}, 5);
  for (std::size_t k = 0; k < 30; ++k) {
    mapper.addKeyframe(k, kStartS + static_cast<double>(k), truth[k]);
    mapper.addGnssFix(fixes[k]);
  }
  mapper.finish();
  EXPECT_FALSE(mapper.gnssReport().has_value());
  EXPECT_TRUE(mapper.graph().gnss().empty());
}

TEST(GnssFusion, ConfigRejectsBadGnssFieldsByName) {
  MappingConfig config;
  config.gnss_huber_sigmas = 0.0;
  EXPECT_THROW(
      {
        try {
          config.validate();
        } catch (const std::exception& e) {
          EXPECT_NE(std::string(e.what()).find("gnss_huber_sigmas"), std::string::npos) << e.what();
          throw;
        }
      },
      std::exception);
  config = MappingConfig{};
  config.gnss_min_fixes = 2;
  EXPECT_THROW(config.validate(), std::exception);
  GeorefConfig gnss;
  gnss.error_correlation_time_s = -1.0;
  EXPECT_THROW(gnss.validate(), std::exception);
}

TEST(GnssFusion, TakesTheAntennaLeverArmFromTheGeorefSection) {
  // The antenna on a 1.5 m pole 0.5 m ahead of the body origin: with georef.p_body_antenna_m
  // the map lands where it belongs; without, 1.5 m too high and the forward offset turns with
  // the walk's heading.
  const std::vector<lie::SE3> truth = trueRectangle();
  const std::vector<lie::SE3> odometry = driftingOdometry(truth);
  const FixNoise on_a_pole{.p_body_antenna_m = Eigen::Vector3d(0.5, 0.0, 1.5)};
  const std::vector<GnssFix> fixes = fixesFor(truth, on_a_pole, 6);
  GeorefConfig gnss = whiteGnss();
  gnss.p_body_antenna_m = on_a_pole.p_body_antenna_m;
  const Fused with = fuse(fusionConfig(), odometry, fixes, gnss);
  const Fused without = fuse(fusionConfig(), odometry, fixes);
  const lie::SE3 expected = trueEnuWorldAtFirstFix(fixes.front());
  EXPECT_LT(georefRms(with, expected, truth), 0.2);
  EXPECT_GT(georefRms(without, expected, truth), 1.4);
}

}  // namespace
}  // namespace taiga::mapping
