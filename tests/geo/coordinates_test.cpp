// Projections checked against values computed here from the definitions (transverse Mercator on
// the central meridian: northing = k0 x meridian arc; the series for the meridian convergence and
// the point scale) and a published point; ECEF against the closed-form formula; round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/geo/coordinates.hpp"

namespace taiga::geo {
namespace {
constexpr double kA = 6378137.0;
constexpr double kInvFlatteningGrs80 = 298.257222101;  // ETRS89
constexpr double kInvFlatteningWgs84 = 298.257223563;

/// Length of the meridian from the equator to `lat_deg` on an ellipsoid (Simpson's rule on
/// M(phi) = a (1 - e^2) / (1 - e^2 sin^2 phi)^(3/2)), independent of PROJ's series.
double meridianArc_m(double lat_deg, double inverse_flattening) {
  const double f = 1.0 / inverse_flattening, e2 = f * (2.0 - f);
  const int n = 20000;
  const double h = lat_deg * kRadPerDeg / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double s = std::sin(i * h);
    const double m = kA * (1.0 - e2) / std::pow(1.0 - e2 * s * s, 1.5);
    sum += m * (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0));
  }
  return sum * h / 3.0;
}

TEST(CoordinateConverter, Tm35finOnTheCentralMeridianIsTheScaledMeridianArc) {
  const CoordinateConverter tm35fin;  // EPSG:3067: central meridian 27 E, k0 0.9996, E0 500 km
  EXPECT_EQ(tm35fin.epsg(), 3067);
  EXPECT_NE(tm35fin.crsName().find("TM35FIN"), std::string::npos) << tm35fin.crsName();
  for (const double lat : {60.0, 61.0, 66.5, 69.8}) {
    const Eigen::Vector3d enh = tm35fin.toProjected({lat, 27.0, 87.5});
    EXPECT_NEAR(enh.x(), 500000.0, 1e-6) << lat;
    EXPECT_NEAR(enh.y(), 0.9996 * meridianArc_m(lat, kInvFlatteningGrs80), 1e-4) << lat;
    EXPECT_DOUBLE_EQ(enh.z(), 87.5);  // ellipsoidal height passes through
  }
}

TEST(CoordinateConverter, HelsinkiInTm35fin) {
  // Helsinki cathedral area, 60.1699 N 24.9384 E: E 385611.3 N 6672118.4 (the value the National
  // Land Survey's converter gives for EUREF-FIN -> ETRS-TM35FIN).
  const CoordinateConverter tm35fin(3067);
  const Eigen::Vector3d enh = tm35fin.toProjected({60.1699, 24.9384, 0.0});
  EXPECT_NEAR(enh.x(), 385611.3, 0.1);
  EXPECT_NEAR(enh.y(), 6672118.4, 0.1);
}

TEST(CoordinateConverter, GivesTheCrsAsWktForLasHeaders) {
  const CoordinateConverter tm35fin(3067);
  EXPECT_EQ(tm35fin.wkt().rfind("PROJCS[\"ETRS89 / TM35FIN(E,N)\"", 0), 0u) << tm35fin.wkt();
  EXPECT_NE(tm35fin.wkt().find("AUTHORITY[\"EPSG\",\"3067\"]"), std::string::npos);
  const CoordinateConverter utm(32635);
  EXPECT_NE(utm.wkt().find("UTM zone 35N"), std::string::npos) << utm.wkt();
}

TEST(CoordinateConverter, UtmZonesNorthAndSouth) {
  // EPSG:32633, UTM 33N: central meridian 15 E; EPSG:32735, UTM 35S: 27 E with N0 = 10 000 km.
  const CoordinateConverter utm33n(32633), utm35s(32735);
  const Eigen::Vector3d north = utm33n.toProjected({45.0, 15.0, 0.0});
  EXPECT_NEAR(north.x(), 500000.0, 1e-6);
  EXPECT_NEAR(north.y(), 0.9996 * meridianArc_m(45.0, kInvFlatteningWgs84), 1e-4);
  const Eigen::Vector3d south = utm35s.toProjected({-33.9, 27.0, 0.0});
  EXPECT_NEAR(south.x(), 500000.0, 1e-6);
  EXPECT_NEAR(south.y(), 1e7 - 0.9996 * meridianArc_m(33.9, kInvFlatteningWgs84), 1e-4);
  // UTM 35N and TM35FIN share every parameter but the ellipsoid (WGS84 vs GRS80, 0.1 mm apart).
  const CoordinateConverter utm35n(32635), tm35fin(3067);
  const Geodetic p{62.3, 22.1, 100.0};
  EXPECT_LT((utm35n.toProjected(p) - tm35fin.toProjected(p)).norm(), 1e-3);
  EXPECT_GT((utm33n.toProjected(p) - tm35fin.toProjected(p)).norm(), 1e5);  // another zone
}

TEST(CoordinateConverter, ProjectedRoundTrip) {
  const CoordinateConverter tm35fin;
  for (const Geodetic& p : {Geodetic{61.0, 24.5, 120.0}, Geodetic{69.9, 29.1, -5.0},
                            Geodetic{59.8, 20.6, 3000.0}}) {
    const Geodetic back = tm35fin.fromProjected(tm35fin.toProjected(p));
    EXPECT_NEAR(back.latitude_deg, p.latitude_deg, 1e-10);  // ~10 micrometres
    EXPECT_NEAR(back.longitude_deg, p.longitude_deg, 1e-10);
    EXPECT_DOUBLE_EQ(back.height_m, p.height_m);
  }
}

TEST(CoordinateConverter, EcefMatchesTheClosedFormAndRoundTrips) {
  const CoordinateConverter converter;
  const double f = 1.0 / kInvFlatteningWgs84, e2 = f * (2.0 - f);
  for (const Geodetic& p : {Geodetic{61.0, 24.5, 120.0}, Geodetic{-45.0, -170.0, 5000.0},
                            Geodetic{0.0, 0.0, 0.0}}) {
    const double lat = p.latitude_deg * kRadPerDeg, lon = p.longitude_deg * kRadPerDeg;
    const double n = kA / std::sqrt(1.0 - e2 * std::sin(lat) * std::sin(lat));
    const Eigen::Vector3d expected((n + p.height_m) * std::cos(lat) * std::cos(lon),
                                   (n + p.height_m) * std::cos(lat) * std::sin(lon),
                                   (n * (1.0 - e2) + p.height_m) * std::sin(lat));
    const Eigen::Vector3d p_ecef = converter.toEcef(p);
    EXPECT_LT((p_ecef - expected).norm(), 1e-6);
    const Geodetic back = converter.fromEcef(p_ecef);
    EXPECT_NEAR(back.latitude_deg, p.latitude_deg, 1e-11);
    EXPECT_NEAR(back.longitude_deg, p.longitude_deg, 1e-11);
    EXPECT_NEAR(back.height_m, p.height_m, 1e-6);
  }
}

TEST(CoordinateConverter, LocalEnu) {
  const CoordinateConverter converter;
  const Geodetic origin{61.0, 24.5, 120.0};
  const Eigen::Vector3d up = converter.toEnu(origin, {61.0, 24.5, 130.0});
  EXPECT_LT((up - Eigen::Vector3d(0, 0, 10)).norm(), 1e-6);
  // 1e-4 deg north: the meridian radius of curvature times the angle (to ~1e-8 relative).
  const double f = 1.0 / kInvFlatteningWgs84, e2 = f * (2.0 - f), s = std::sin(61.0 * kRadPerDeg);
  const double meridian_radius = kA * (1.0 - e2) / std::pow(1.0 - e2 * s * s, 1.5) + 120.0;
  const Eigen::Vector3d north = converter.toEnu(origin, {61.0001, 24.5, 120.0});
  EXPECT_NEAR(north.y(), meridian_radius * 1e-4 * kRadPerDeg, 1e-5);
  EXPECT_NEAR(north.x(), 0.0, 1e-9);
  const Eigen::Vector3d p_enu(-123.4, 56.7, 8.9);
  EXPECT_LT((converter.toEnu(origin, converter.fromEnu(origin, p_enu)) - p_enu).norm(), 1e-8);
}

TEST(CoordinateConverter, GridTangentAtTheSimulatorsOrigin) {
  const CoordinateConverter tm35fin;
  const Geodetic origin{61.0, 24.5, 120.0};
  const GridTangent tangent = tm35fin.gridTangent(origin);
  // Series for a transverse Mercator grid (Snyder, Map Projections, eqs. 8-12 and 8-13) with
  // l = (lon - lon_0) cos(lat), eta^2 = e'^2 cos^2(lat):
  //   convergence = (lon - lon_0) sin(lat) (1 + l^2 (1 + 3 eta^2) / 3 + ...)
  //   scale       = k0 (1 + l^2 (1 + eta^2) / 2 + l^4 (5 - 4 t^2 + 42 eta^2 + 13 eta^4 - 28 e'^2) / 24)
  // with t = tan(lat) (Snyder eq. 8-11)
  const double f = 1.0 / kInvFlatteningGrs80, e2 = f * (2.0 - f), ep2 = e2 / (1.0 - e2);
  const double lat = 61.0 * kRadPerDeg, dlon = (24.5 - 27.0) * kRadPerDeg;
  const double l2 = std::pow(dlon * std::cos(lat), 2), eta2 = ep2 * std::pow(std::cos(lat), 2);
  const double convergence_deg =
      dlon * std::sin(lat) * (1.0 + l2 * (1.0 + 3.0 * eta2) / 3.0) * kDegPerRad;
  EXPECT_NEAR(tangent.yaw_deg, convergence_deg, 2e-6);  // first order alone is 3e-4 deg off
  EXPECT_LT(tangent.yaw_deg, -2.0);                      // west of 27 E: grid north east of true
  // Grid metres per local metre at the origin's height: the point scale times R / (R + h), with
  // R the Gaussian radius sqrt(M N) (the height reduction, 19 ppm at 120 m).
  const double w = 1.0 - e2 * std::sin(lat) * std::sin(lat);
  const double gaussian_radius = kA * std::sqrt(1.0 - e2) / w;
  const double height_reduction = gaussian_radius / (gaussian_radius + origin.height_m);
  const double t2 = std::pow(std::tan(lat), 2);
  const double point_scale =
      0.9996 * (1.0 + l2 * (1.0 + eta2) / 2.0 +
                l2 * l2 * (5.0 - 4.0 * t2 + 42.0 * eta2 + 13.0 * eta2 * eta2 - 28.0 * ep2) / 24.0);
  EXPECT_NEAR(tangent.scale, point_scale * height_reduction, 3e-8);  // series truncated at l^4

  // The tangent-plane map against the exact conversion across a plot.
  double max_error_50_m = 0.0, max_error_150_m = 0.0, max_error_rigid_150_m = 0.0;
  Eigen::Matrix4d T_rigid = tangent.T_grid_enu;
  T_rigid.topLeftCorner<2, 2>() /= tangent.scale;
  for (int i = 0; i < 16; ++i) {
    const double az = i * std::numbers::pi / 8.0;
    for (const double d : {50.0, 150.0}) {
      const Eigen::Vector4d p_enu(d * std::cos(az), d * std::sin(az), 3.0, 1.0);
      const Eigen::Vector3d exact = tm35fin.toProjected(tm35fin.fromEnu(origin, p_enu.head<3>()));
      const double error = ((tangent.T_grid_enu * p_enu).head<3>() - exact).norm();
      (d < 100.0 ? max_error_50_m : max_error_150_m) =
          std::max(d < 100.0 ? max_error_50_m : max_error_150_m, error);
      if (d > 100.0) {
        max_error_rigid_150_m =
            std::max(max_error_rigid_150_m, ((T_rigid * p_enu).head<3>() - exact).norm());
      }
    }
  }
  EXPECT_LT(max_error_50_m, 0.5e-3);
  EXPECT_LT(max_error_150_m, 3e-3);
  EXPECT_GT(max_error_rigid_150_m, 0.02);  // why the scale is part of T_grid_enu
  std::cout << "tangent plane error: " << max_error_50_m * 1e3 << " mm at 50 m, "
            << max_error_150_m * 1e3 << " mm at 150 m; without the scale "
            << max_error_rigid_150_m * 1e3 << " mm at 150 m\n";
}

TEST(CoordinateConverter, UnknownOrUnprojectedCodesAreInputErrors) {
  try {
    CoordinateConverter converter(999999);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("EPSG:999999: unknown CRS code"), std::string::npos)
        << e.what();
  }
  try {
    CoordinateConverter converter(4326);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("EPSG:4326: 'WGS 84' is not a projected CRS"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace taiga::geo
