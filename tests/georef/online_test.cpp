// The online georeferencer: fed the odometry's poses and the fixes as a run delivers them, it
// has no estimate until the walk determines the heading, then recovers the known T_enu_world,
// ends with exactly the offline robust fit of the same fixes, and follows a change of the
// odometry's world frame.
#include "taiga/georef/online.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "taiga/core/angles.hpp"

namespace taiga::georef {
namespace {

const geo::Geodetic kOrigin{61.0, 24.5, 120.0};
const lie::SE3 kTruth_T_enu_world(lie::SO3::fromRollPitchYaw(0.0, 0.0, 37.0 * kRadPerDeg),
                                  Eigen::Vector3d(312.5, -457.25, 23.1));

/// A 120 s walk around a 20 m circle, one pose per 0.1 s; fixes at 1 Hz with 0.5 m white noise.
struct Walk {
  Trajectory poses;
  std::vector<GnssFix> fixes;
};

Walk makeWalk() {
  Walk walk;
  const geo::CoordinateConverter converter(3067);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (int k = 0; k <= 1200; ++k) {
    const double t = 100.0 + 0.1 * k, angle = 0.05 * 0.1 * k;
    const lie::SE3 T_world_body(lie::SO3::fromRollPitchYaw(0.0, 0.0, angle + 1.5708),
                                Eigen::Vector3d(20.0 * std::cos(angle), 20.0 * std::sin(angle), 0.0));
    walk.poses.append(t, T_world_body);
    if (k % 10 != 0) continue;
    const Eigen::Vector3d p_enu =
        kTruth_T_enu_world * T_world_body.translation() +
        Eigen::Vector3d(noise(rng), noise(rng), 2.0 * noise(rng));
    const geo::Geodetic g = converter.fromEnu(kOrigin, p_enu);
    GnssFix fix{.t_s = t, .latitude_deg = g.latitude_deg, .longitude_deg = g.longitude_deg,
                .height_ellipsoid_m = g.height_m};
    fix.covariance_enu_m2 = Eigen::Vector3d(0.25, 0.25, 1.0).asDiagonal();
    fix.covariance_type = GnssCovarianceType::kDiagonalKnown;
    fix.status = GnssStatus::kFix;
    walk.fixes.push_back(fix);
  }
  return walk;
}

GeorefSettings whiteNoiseSettings() {
  GeorefSettings settings;
  settings.fit.error_correlation_time_s = 0.0;
  return settings;
}

/// Feeds the walk as a run would: each fix when it is received, a pose each 0.1 s.
void feed(OnlineGeoreferencer& online, const Walk& walk, const lie::SE3& T_frame_world,
          std::vector<std::optional<OnlineEstimate>>* history = nullptr) {
  std::size_t next_fix = 0;
  for (const StampedPose& p : walk.poses) {
    while (next_fix < walk.fixes.size() && walk.fixes[next_fix].t_s <= p.t_s)
      online.addFix(walk.fixes[next_fix++]);
    online.addPose(p.t_s, T_frame_world * p.pose);
    if (history) history->push_back(online.estimate());
  }
}

TEST(OnlineGeoreferencer, WaitsForTheHeadingThenRecoversTheTransform) {
  const Walk walk = makeWalk();
  OnlineGeoreferencer online(whiteNoiseSettings());
  std::vector<std::optional<OnlineEstimate>> history;
  feed(online, walk, lie::SE3(), &history);
  EXPECT_FALSE(history[5].has_value());  // one fix, no heading yet
  ASSERT_TRUE(history[300].has_value());  // 30 s, 30 m of arc
  ASSERT_TRUE(online.estimate().has_value());
  const GeorefFit& fit = online.estimate()->fit;
  EXPECT_EQ(online.estimate()->fixes, 121u);
  // 121 fixes of 0.5 m spread over a 20 m circle: yaw sigma ~ 0.5 / (11 * 20) rad = 0.13 deg.
  const Eigen::Vector3d rotation_error =
      (fit.T_enu_world.rotation() * kTruth_T_enu_world.rotation().inverse()).Log();
  EXPECT_LT(std::abs(rotation_error.z()), 0.5 * kRadPerDeg);
  // Positions in the grid (the estimator's ENU origin is its first fix, not kOrigin).
  const geo::CoordinateConverter converter(3067);
  for (const StampedPose& p : {walk.poses.front(), walk.poses.back()}) {
    const std::optional<GridPose> grid = online.toGrid(p.t_s, p.pose);
    ASSERT_TRUE(grid.has_value());
    const Eigen::Vector3d truth = converter.toProjected(
        converter.fromEnu(kOrigin, kTruth_T_enu_world * p.pose.translation()));
    EXPECT_LT(std::hypot(grid->easting_m - truth.x(), grid->northing_m - truth.y()), 0.3);
    EXPECT_LT(std::abs(grid->height_m - truth.z()), 0.6);
  }
  // The estimate is refitted as fixes come: the reported yaw sigma shrinks.
  EXPECT_LT(history[300]->fixes, online.estimate()->fixes);
  EXPECT_LT(fit.sigma[5], history[300]->fit.sigma[5]);
}

TEST(OnlineGeoreferencer, EndsWithTheOfflineRobustFitOfTheSameFixes) {
  const Walk walk = makeWalk();
  OnlineGeoreferencer online(whiteNoiseSettings());
  feed(online, walk, lie::SE3());
  ASSERT_TRUE(online.estimate().has_value());
  ASSERT_TRUE(online.estimate()->fit.error_model.has_value());
  // The same fixes under the error model the online estimator chose last.
  GeorefSettings settings = whiteNoiseSettings();
  settings.fit.error_model = online.estimate()->fit.error_model;
  const geo::CoordinateConverter converter(settings.epsg);
  const PreparedFixes prepared = prepareFixes(walk.fixes, settings.gating, converter);
  const Association offline = associateFixes(walk.poses, prepared.fixes, settings.association);
  const GeorefFit expected = fitRobust(offline.pairs, settings.fit);
  ASSERT_TRUE(online.estimate().has_value());
  EXPECT_EQ(online.estimate()->fit.T_enu_world.matrix(), expected.T_enu_world.matrix());
  EXPECT_EQ(online.estimate()->fit.sigma, expected.sigma);
  // And a pose in the grid is what the offline chain gives.
  const StampedPose& last = walk.poses.back();
  const std::optional<GridPose> live = online.toGrid(last.t_s, last.pose);
  Trajectory one;
  one.append(last.t_s, last.pose);
  const GridPose offline_pose =
      trajectoryInGrid(one, expected.T_enu_world, prepared.origin, converter).front();
  ASSERT_TRUE(live.has_value());
  EXPECT_DOUBLE_EQ(live->easting_m, offline_pose.easting_m);
  EXPECT_DOUBLE_EQ(live->northing_m, offline_pose.northing_m);
}

}  // namespace
}  // namespace taiga::georef
