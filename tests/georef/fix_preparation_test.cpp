// Fix preparation (gating, local ENU), association with a trajectory by time, and the grid output.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "synthetic_fixes.hpp"
#include "taiga/georef/association.hpp"
#include "taiga/georef/fix_preparation.hpp"
#include "taiga/georef/grid_output.hpp"

namespace taiga::georef {
namespace {

GnssFix fixAt(const geo::CoordinateConverter& converter, const geo::Geodetic& origin,
              const Eigen::Vector3d& p_enu, double t_s, double sigma_m = 1.0) {
  const geo::Geodetic point = converter.fromEnu(origin, p_enu);
  GnssFix fix;
  fix.t_s = t_s;
  fix.latitude_deg = point.latitude_deg;
  fix.longitude_deg = point.longitude_deg;
  fix.height_ellipsoid_m = point.height_m;
  fix.covariance_enu_m2 = Eigen::Vector3d(sigma_m * sigma_m, 0.25 * sigma_m * sigma_m, 4.0).asDiagonal();
  fix.covariance_type = GnssCovarianceType::kDiagonalKnown;
  fix.status = GnssStatus::kFix;
  return fix;
}

const geo::Geodetic kSite{61.0, 24.5, 120.0};

TEST(FixPreparation, GatesPoorFixesAndPutsTheOriginAtTheFirstGoodOne) {
  const geo::CoordinateConverter converter;
  std::vector<GnssFix> fixes;
  fixes.push_back(fixAt(converter, kSite, {0, 0, 0}, 1.0));
  fixes.back().status = GnssStatus::kNoFix;
  fixes.push_back(fixAt(converter, kSite, {5, 0, 0}, 2.0, 6.0));  // east sigma 6 m > 5 m
  fixes.push_back(fixAt(converter, kSite, {10, 20, 1}, 3.0));      // the first good fix
  fixes.push_back(fixAt(converter, kSite, {40, -30, 2}, 4.0));
  fixes.push_back(fixAt(converter, kSite, {50, 0, 0}, 5.0));
  fixes.back().latitude_deg = std::nan("");
  fixes.push_back(fixAt(converter, kSite, {60, 0, 0}, 6.0));
  fixes.back().covariance_enu_m2(2, 2) = -1.0;  // not positive-definite
  fixes.push_back(fixAt(converter, kSite, {70, 0, 0}, 7.0));
  fixes.back().covariance_type = GnssCovarianceType::kUnknown;  // the default covariance

  const PreparedFixes prepared = prepareFixes(fixes, FixGating{}, converter);
  EXPECT_EQ(prepared.total, 7u);
  EXPECT_EQ(prepared.gated_no_fix, 1u);
  EXPECT_EQ(prepared.gated_sigma, 1u);
  EXPECT_EQ(prepared.gated_invalid, 2u);
  EXPECT_EQ(prepared.gated(), 4u);
  ASSERT_EQ(prepared.fixes.size(), 3u);
  EXPECT_NEAR(prepared.origin.latitude_deg, fixes[2].latitude_deg, 0.0);
  EXPECT_LT(prepared.fixes[0].p_enu.norm(), 1e-9);
  // The ENU frame at the first good fix differs from the one at the site by the offset and
  // (over 40 m) a turn below 1e-5 rad: positions relative to the first fix are kept.
  EXPECT_LT((prepared.fixes[1].p_enu - Eigen::Vector3d(30, -50, 1)).norm(), 2e-3);
  EXPECT_EQ(prepared.fixes[1].covariance_enu_m2, fixes[3].covariance_enu_m2);
  EXPECT_EQ(prepared.fixes[2].covariance_enu_m2.diagonal(), Eigen::Vector3d(4.0, 4.0, 16.0));

  // A given origin is used as it is.
  const PreparedFixes at_site = prepareFixes(fixes, FixGating{}, converter, kSite);
  EXPECT_LT((at_site.fixes[0].p_enu - Eigen::Vector3d(10, 20, 1)).norm(), 1e-6);

  // A looser gate lets the 6 m fix through.
  FixGating loose;
  loose.max_horizontal_sigma_m = 7.0;
  EXPECT_EQ(prepareFixes(fixes, loose, converter).fixes.size(), 4u);
  EXPECT_THROW(FixGating{.max_horizontal_sigma_m = 0.0}.validate(), std::invalid_argument);
}

TEST(FixPreparation, HorizontalSigmaIsTheLargerAxisOfTheEastNorthEllipse) {
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  covariance.topLeftCorner<2, 2>() << 2.0, 1.0, 1.0, 2.0;  // axes 3 and 1 m^2
  covariance(2, 2) = 100.0;                                 // the vertical does not count
  EXPECT_NEAR(horizontalSigma(covariance), std::sqrt(3.0), 1e-12);
}

TEST(Association, InterpolatesOnSe3AndDropsFixesOutsideTheSpanOrInGaps) {
  // Poses at 0, 1, 2 s moving 1 m/s along x while turning 10 deg/s, then a 5 s gap, then 8 s.
  Trajectory trajectory;
  for (const double t : {0.0, 1.0, 2.0, 7.0, 8.0})
    trajectory.append(t, lie::SE3(lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), test::deg(10.0 * t)),
                                  Eigen::Vector3d(t, 0.0, 0.0)));
  std::vector<LocalFix> fixes;
  for (const double t : {-0.5, 0.5, 2.0, 4.0, 7.5, 8.5}) fixes.push_back({t, Eigen::Vector3d::Zero()});
  AssociationOptions options;
  options.p_body_antenna = Eigen::Vector3d(0.0, 0.0, 0.3);
  const Association association = associateFixes(trajectory, fixes, options);
  EXPECT_EQ(association.outside_span, 2u);  // -0.5 and 8.5
  EXPECT_EQ(association.in_gap, 1u);        // 4.0
  ASSERT_EQ(association.pairs.size(), 3u);
  EXPECT_EQ(association.pairs[0].fix.t_s, 0.5);
  const lie::SE3 expected = lie::interpolate(trajectory[0].pose, trajectory[1].pose, 0.5);
  EXPECT_LT((association.pairs[0].T_world_body.matrix() - expected.matrix()).norm(), 1e-12);
  EXPECT_LT((association.pairs[0].p_world - expected * options.p_body_antenna).norm(), 1e-12);
  // On the SE(3) geodesic (a screw), not on the straight line between the positions.
  EXPECT_GT((expected.translation() - Eigen::Vector3d(0.5, 0.0, 0.0)).norm(), 1e-3);
  EXPECT_LT(association.pairs[1].T_world_body.minus(trajectory[2].pose).norm(), 1e-12);  // at a pose
  EXPECT_EQ(association.pairs[2].fix.t_s, 7.5);
  // With a larger gap allowed, the fix at 4 s is kept.
  options.max_gap_s = 6.0;
  EXPECT_EQ(associateFixes(trajectory, fixes, options).pairs.size(), 4u);
}

TEST(GridOutput, ExactPerPoseAndTheTangentPlaneWithinMillimetres) {
  const geo::CoordinateConverter tm35fin(3067);
  const lie::SE3 T_enu_world(lie::SO3::fromRollPitchYaw(0.0, 0.0, test::deg(37.0)),
                             Eigen::Vector3d(30.0, -20.0, 1.0));
  Trajectory trajectory;
  // Body x axis pointing along world y (yaw 90 deg in the world): 127 deg from ENU east.
  const lie::SO3 R_world_body = lie::SO3::fromRollPitchYaw(0.0, 0.0, test::deg(90.0));
  for (int k = 0; k < 5; ++k)
    trajectory.append(k, lie::SE3(R_world_body, Eigen::Vector3d(25.0 * k, 10.0 * k, 0.5 * k)));
  const auto grid = trajectoryInGrid(trajectory, T_enu_world, kSite, tm35fin);
  const Eigen::Matrix4d T_epsg_world = tangentPlaneEpsgWorld(T_enu_world, kSite, tm35fin);
  const double convergence_deg = tm35fin.gridTangent(kSite).yaw_deg;
  ASSERT_EQ(grid.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    const Eigen::Vector3d p_world = trajectory[k].pose.translation();
    const Eigen::Vector3d exact =
        tm35fin.toProjected(tm35fin.fromEnu(kSite, T_enu_world * p_world));
    EXPECT_NEAR(grid[k].easting_m, exact.x(), 1e-9);
    EXPECT_NEAR(grid[k].northing_m, exact.y(), 1e-9);
    EXPECT_NEAR(grid[k].height_m, exact.z(), 1e-9);
    // Within 120 m of the origin the tangent plane is good to about a millimetre.
    const Eigen::Vector3d tangent = (T_epsg_world * p_world.homogeneous()).head<3>();
    EXPECT_LT((tangent - exact).norm(), 2e-3) << k;
    // Yaw: 127 deg from east plus the convergence (-2.19 deg here), to within the turn of the
    // local frame over 120 m (0.001 deg).
    EXPECT_NEAR(grid[k].yaw_grid_deg, 127.0 + convergence_deg, 2e-3) << k;
  }
  EXPECT_NEAR(convergence_deg, -2.1869, 1e-3);  // docs/simulator.md
}

}  // namespace
}  // namespace taiga::georef
