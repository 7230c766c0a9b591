// The fixes CSV reader (the format of docs/georeferencing.md) and the georef.yaml and
// trajectory.geojson writers.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../support/temp_dir.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/georef/georef_files.hpp"

namespace taiga::georef {
namespace {

using ::testing::HasSubstr;

std::string errorOf(const std::filesystem::path& path) {
  try {
    readFixesCsv(path);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << path << " was read without an error";
  return "";
}

TEST(FixesCsv, ReadsColumnsInAnyOrderWithSigmasAndStatus) {
  test::TempDir dir;
  const auto path = dir.write("fixes.csv",
                              "# comment\n"
                              "latitude_deg, longitude_deg, t_s, height_m, status, sigma_up_m, "
                              "sigma_east_m, sigma_north_m\n"
                              "\n"
                              "61.0000001,24.5000002,1700000000.25,120.5,0,3,1.5,2\n"
                              "61.1,24.6,1700000001.25,121,-1,3,1.5,2\n");
  const std::vector<GnssFix> fixes = readFixesCsv(path);
  ASSERT_EQ(fixes.size(), 2u);
  EXPECT_EQ(fixes[0].t_s, 1700000000.25);
  EXPECT_EQ(fixes[0].latitude_deg, 61.0000001);
  EXPECT_EQ(fixes[0].longitude_deg, 24.5000002);
  EXPECT_EQ(fixes[0].height_ellipsoid_m, 120.5);
  EXPECT_EQ(fixes[0].covariance_enu_m2.diagonal(), Eigen::Vector3d(2.25, 4.0, 9.0));
  EXPECT_EQ(fixes[0].covariance_type, GnssCovarianceType::kDiagonalKnown);
  EXPECT_EQ(fixes[0].status, GnssStatus::kFix);
  EXPECT_EQ(fixes[1].status, GnssStatus::kNoFix);
}

TEST(FixesCsv, WithoutSigmasTheCovarianceIsUnknown) {
  test::TempDir dir;
  const auto fixes = readFixesCsv(
      dir.write("fixes.csv", "t_s,latitude_deg,longitude_deg,height_m\n1,61,24.5,120\n"));
  ASSERT_EQ(fixes.size(), 1u);
  EXPECT_EQ(fixes[0].covariance_type, GnssCovarianceType::kUnknown);
}

TEST(FixesCsv, MalformedFilesNameTheLineAndColumn) {
  test::TempDir dir;
  const std::string header = "t_s,latitude_deg,longitude_deg,height_m";
  EXPECT_THAT(errorOf(dir.write("a.csv", header + ",sigma_east_m\n")),
              HasSubstr("a.csv:1: give all three of sigma_east_m, sigma_north_m, sigma_up_m or none"));
  EXPECT_THAT(errorOf(dir.write("b.csv", header + ",t_s\n")),
              HasSubstr("b.csv:1: column 't_s' appears twice"));
  EXPECT_THAT(errorOf(dir.write("c.csv", header + "\n1,61,24.5\n")),
              HasSubstr("c.csv:2: 3 values, the header has 4 columns"));
  EXPECT_THAT(errorOf(dir.write("d.csv", header + "\n1,91,24.5,100\n")),
              HasSubstr("d.csv:2: column 'latitude_deg': 91 is outside [-90, 90]"));
  EXPECT_THAT(errorOf(dir.write("e.csv", header + "\n2,61,24.5,100\n2,61,24.5,100\n")),
              HasSubstr("e.csv:3: column 't_s': 2 is not after the previous fix's 2"));
  EXPECT_THAT(errorOf(dir.write("f.csv", header + ",status\n1,61,24.5,100,7\n")),
              HasSubstr("f.csv:2: column 'status': expected -1 (no fix), 0 (fix), 1 (SBAS) or 2"));
  EXPECT_THAT(errorOf(dir.write("g.csv", header + ",sigma_east_m,sigma_north_m,sigma_up_m\n1,61,24.5,100,0,1,1\n")),
              HasSubstr("g.csv:2: column 'sigma_east_m': a sigma must be positive, got 0"));
  EXPECT_THAT(errorOf(dir.write("h.csv", "# only a comment\n")), HasSubstr("h.csv: empty file"));
  EXPECT_THAT(errorOf(dir.write("i.csv", header + "\n1,61,24.5,nan\n")),
              HasSubstr("i.csv:2: column 'height_m': expected a finite number, got 'nan'"));
}

TEST(GeorefYaml, HoldsTheTransformsSigmasAndCountsAtFullPrecision) {
  test::TempDir dir;
  GeorefReport report;
  report.method = "robust";
  report.crs_name = "ETRS89 / TM35FIN(E,N)";
  report.origin = {61.000000123456789, 24.5, 120.25};
  report.origin_grid = {364808.14192166715, 6765367.581224121, 120.25};
  report.fit.T_enu_world = lie::SE3(lie::SO3::fromRollPitchYaw(0.0, 0.0, 0.3), Eigen::Vector3d(1.0 / 3.0, 2, 3));
  report.fit.sigma << 0.1, 0.2, 0.3, 0.001, 0.002, 0.003;
  report.fit.inliers = 40;
  report.fit.outliers = 2;
  report.T_epsg_world(0, 3) = 364808.14192166715;
  report.fixes_total = 50;
  report.gated_sigma = 8;
  writeGeorefYaml(dir.file("georef.yaml"), report);
  const YAML::Node yaml = YAML::LoadFile(dir.file("georef.yaml").string());
  EXPECT_EQ(yaml["method"].as<std::string>(), "robust");
  EXPECT_EQ(yaml["crs_name"].as<std::string>(), "ETRS89 / TM35FIN(E,N)");
  EXPECT_EQ(yaml["enu_origin"]["latitude_deg"].as<double>(), 61.000000123456789);
  EXPECT_EQ(yaml["T_enu_world"][0][3].as<double>(), 1.0 / 3.0);
  EXPECT_EQ(yaml["T_epsg_world"][0][3].as<double>(), 364808.14192166715);
  EXPECT_NEAR(yaml["T_enu_world_roll_pitch_yaw_deg"][2].as<double>(), 0.3 * kDegPerRad, 1e-12);
  EXPECT_NEAR(yaml["sigma"]["yaw_deg"].as<double>(), 0.003 * kDegPerRad, 1e-12);
  EXPECT_EQ(yaml["sigma"]["north_m"].as<double>(), 0.2);
  EXPECT_EQ(yaml["fixes"]["total"].as<int>(), 50);
  EXPECT_EQ(yaml["fixes"]["gated_sigma"].as<int>(), 8);
  EXPECT_EQ(yaml["fixes"]["used"].as<int>(), 40);
  EXPECT_EQ(yaml["fixes"]["outliers"].as<int>(), 2);
  // What `taiga georef --als` reads back: the grid and the 1-sigma that sets its search.
  const GeorefGrid grid = readGeorefGrid(dir.file("georef.yaml"));
  EXPECT_EQ(grid.T_epsg_world(0, 3), 364808.14192166715);
  ASSERT_TRUE(grid.sigma_horizontal_m && grid.sigma_yaw_deg);
  EXPECT_NEAR(*grid.sigma_horizontal_m, std::hypot(0.1, 0.2), 1e-15);
  EXPECT_NEAR(*grid.sigma_yaw_deg, 0.003 * kDegPerRad, 1e-12);
}

TEST(GeorefYaml, QuotedNamesAndNonFiniteSigmasReadBack) {
  test::TempDir dir;
  GeorefReport report;
  report.method = "closed";
  report.trajectory_file = R"(runs/a "b"\c: #1.tum)";
  report.gnss_file = "fixes.csv";
  report.fit.sigma << 0.1, 0.2, 0.3, 0.001, 0.002, std::numeric_limits<double>::quiet_NaN();
  report.fit.sigma[2] = std::numeric_limits<double>::infinity();
  report.fit.converged = false;
  writeGeorefYaml(dir.file("georef.yaml"), report);
  const YAML::Node yaml = YAML::LoadFile(dir.file("georef.yaml").string());
  EXPECT_EQ(yaml["trajectory"].as<std::string>(), report.trajectory_file);
  EXPECT_EQ(yaml["gnss"].as<std::string>(), "fixes.csv");
  EXPECT_TRUE(std::isnan(yaml["sigma"]["yaw_deg"].as<double>()));
  EXPECT_EQ(yaml["sigma"]["up_m"].as<double>(), std::numeric_limits<double>::infinity());
  EXPECT_FALSE(yaml["converged"].as<bool>());
  EXPECT_FALSE(readGeorefGrid(dir.file("georef.yaml")).sigma_yaw_deg);  // not finite: none
}

TEST(GeoJson, IsALineStringInTheNamedCrsAtFullPrecision) {
  test::TempDir dir;
  const std::vector<GridPose> poses{{100.25, 364808.14192166715, 6765367.581224121, 120.1, 10.0},
                                    {100.35, 364809.0000000001, 6765368.5, -0.3, 11.0}};
  writeGeoJson(dir.file("trajectory.geojson"), poses, 3067, R"(walk "1")");
  std::ifstream in(dir.file("trajectory.geojson"));
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json geojson = nlohmann::json::parse(text.str());
  EXPECT_EQ(geojson["type"], "FeatureCollection");
  EXPECT_EQ(geojson["name"], R"(walk "1")");
  EXPECT_EQ(geojson["crs"]["properties"]["name"], "urn:ogc:def:crs:EPSG::3067");
  const nlohmann::json& feature = geojson["features"][0];
  EXPECT_EQ(feature["properties"]["t_start_s"].get<double>(), 100.25);
  EXPECT_EQ(feature["properties"]["t_end_s"].get<double>(), 100.35);
  const nlohmann::json& coordinates = feature["geometry"]["coordinates"];
  ASSERT_EQ(coordinates.size(), 2u);
  EXPECT_EQ(coordinates[0][0].get<double>(), 364808.14192166715);
  EXPECT_EQ(coordinates[0][1].get<double>(), 6765367.581224121);
  EXPECT_EQ(coordinates[1][0].get<double>(), 364809.0000000001);
  EXPECT_EQ(coordinates[1][2].get<double>(), -0.3);
}

}  // namespace
}  // namespace taiga::georef
