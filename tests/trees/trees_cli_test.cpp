// `taiga trees` on real terrestrial scans (../shared/data/forest) and on bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"
#include "forest_fixture.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/trees/tree_files.hpp"

namespace taiga {
namespace {

const std::string kForest = "../shared/data/forest/";

// The reference DBH of the single TLS trees was fitted by hand (docs/trees.md, "Real clouds"):
// the points 1.0-1.6 m above the ground (its 0.5th height percentile within 1.5 m of the stem),
// an exhaustive grid over centres (2 cm) and radii (1 cm) scored by the points within 1.5 cm of
// the ring less those more than 5 cm inside it, then least squares on an annulus shrunk to 3x
// the RMS. Pine: centre (-0.0600, 0.1499), DBH 0.2557 m, RMS 6 mm. Spruce (branches from 1 m
// up): centre (0.1580, 0.0041), DBH 0.2430 m, RMS 7 mm.
struct RealTree {
  const char* file;
  Eigen::Vector2d center_m;
  double dbh_m;
};

TEST(TreesCli, RealSingleTreesAgreeWithTheManualFit) {
  for (const RealTree& t : {RealTree{"treels_pine.ply", {-0.0600, 0.1499}, 0.2557},
                            RealTree{"treels_spruce.ply", {0.1580, 0.0041}, 0.2430}}) {
    test::TempDir dir;
    const auto r = test::runTaiga("trees " + kForest + t.file + " --out " + dir.path().string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    // A TLS cloud has no sensor positions per point: the residuals stay across the surface.
    EXPECT_NE(r.output.find("across the surface (no sensor positions"), std::string::npos);
    const auto trees = trees::readTreesCsv(dir.file("trees.csv"));
    ASSERT_EQ(trees.size(), 1u) << t.file << "\n" << r.output;
    EXPECT_NEAR(trees[0].dbh_m, t.dbh_m, 0.01) << t.file;
    EXPECT_LT((trees[0].bh_xy_m - t.center_m).norm(), 0.015) << t.file;
    EXPECT_GT(trees[0].height_m, 15.0) << t.file;  // the clouds reach 16.7 and 19.9 m
    EXPECT_TRUE(std::filesystem::exists(dir.file("trees.geojson")));
    EXPECT_TRUE(std::filesystem::exists(dir.file("dtm.asc")));
    io::LasReader map(dir.file("trees_map.las"));
    EXPECT_GT(map.pointCount(), 70000u);
  }
}

TEST(TreesCli, TheRealPinePlot) {
  // A 10 x 10 m plot, thinned TLS, ground near z = 49 m. Its stems were not counted by hand; 15
  // are found, all of plausible size. The bound says: most are found, none absurd.
  test::TempDir dir;
  const auto r =
      test::runTaiga("trees " + kForest + "treels_pine_plot.ply --out " + dir.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto trees = trees::readTreesCsv(dir.file("trees.csv"));
  EXPECT_GE(trees.size(), 12u);
  EXPECT_LE(trees.size(), 20u);
  for (const auto& t : trees) {
    EXPECT_GT(t.dbh_m, 0.08);
    EXPECT_LT(t.dbh_m, 0.45);
    EXPECT_NEAR(t.ground_z_m, 49.5, 1.5);
  }

  // Every point's height above the ground, read back by an independent LAS reader (copc.js,
  // tools/las-check): a LAS 1.4 extra field; ground points at 0, every point's z less its height
  // on the plot's terrain.
  const auto check = test::runCommand("node tools/las-check/las-check.mjs " +
                                      dir.file("trees_map.las").string() + " 3000");
  ASSERT_EQ(check.exit_code, 0) << check.output << " (run scripts/setup.sh)";
  const nlohmann::json las = nlohmann::json::parse(check.output);
  EXPECT_EQ(las["pointDataRecordLength"], 34);
  ASSERT_EQ(las["extraBytes"].size(), 1u);
  EXPECT_EQ(las["extraBytes"][0]["name"], "HeightAboveGround");
  std::size_t ground = 0, ground_near = 0;
  for (const nlohmann::json& p : las["points"]) {
    const double z = p["Z"], above = p["HeightAboveGround"];
    EXPECT_NEAR(z - above, 49.5, 1.5);
    if (p["Classification"] != 2) continue;
    ++ground;
    ground_near += std::abs(above) < 0.15;
  }
  EXPECT_GT(ground, 100u);
  EXPECT_GT(ground_near, ground * 95 / 100);
}

TEST(TreesCli, ACloudWithoutGroundSaysSo) {
  test::TempDir dir;
  const auto r =
      test::runTaiga("trees " + kForest + "lidr_dbh_slice.ply --out " + dir.path().string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("none found"), std::string::npos) << r.output;
  EXPECT_TRUE(trees::readTreesCsv(dir.file("trees.csv")).empty());
}

TEST(TreesCli, BadInputNamesTheFile) {
  test::TempDir dir;
  const std::string out = " --out " + dir.path().string();
  PointCloud empty;
  io::writePly(dir.file("empty.ply"), empty);
  auto r = test::runTaiga("trees " + dir.file("empty.ply").string() + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("empty.ply"), std::string::npos) << r.output;

  std::ofstream(dir.file("cloud.laz")) << "LASF";
  r = test::runTaiga("trees " + dir.file("cloud.laz").string() + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("LAZ"), std::string::npos) << r.output;

  std::ofstream(dir.file("notes.txt")) << "1 2 3\n";
  r = test::runTaiga("trees " + dir.file("notes.txt").string() + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;

  std::ofstream(dir.file("truncated.ply"))
      << "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty double x\n";
  r = test::runTaiga("trees " + dir.file("truncated.ply").string() + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("truncated.ply"), std::string::npos) << r.output;

  r = test::runTaiga("trees " + dir.path().string() + out);  // a directory without map.las
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("map.las"), std::string::npos) << r.output;
}

TEST(TreesCli, NanPointsAreSkippedAndLargeCoordinatesKeepTheirPrecision) {
  // The synthetic forest moved into EPSG:3067 coordinates, with NaN points among it.
  test::TempDir dir;
  const Eigen::Vector3d offset(364800.0, 6765300.0, 120.0);
  PointCloud cloud;
  for (const Eigen::Vector3d& p : test::syntheticForest({{{1.0, 2.0}, 0.3}}, 0.005, 1, false))
    cloud.positions.push_back(p + offset);
  cloud.positions.insert(cloud.positions.begin() + 10, Eigen::Vector3d::Constant(std::nan("")));
  io::writePly(dir.file("plot.ply"), cloud);
  const auto r = test::runTaiga("trees " + dir.file("plot.ply").string() + " --epsg 3067 --out " +
                                dir.path().string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("NaN"), std::string::npos) << r.output;
  const auto trees = trees::readTreesCsv(dir.file("trees.csv"));
  ASSERT_EQ(trees.size(), 1u) << r.output;
  EXPECT_LT((trees[0].bh_xy_m - Eigen::Vector2d(364801.0, 6765302.0)).norm(), 0.005);
  EXPECT_NEAR(trees[0].dbh_m, 0.3, 0.004);
  std::ifstream geojson(dir.file("trees.geojson"));
  const std::string text((std::istreambuf_iterator<char>(geojson)), {});
  EXPECT_NE(text.find("EPSG::3067"), std::string::npos);
  EXPECT_NE(text.find("364801."), std::string::npos);
}

TEST(TreesCli, EvalNeedsBothTreeLists) {
  const auto r = test::runTaiga(
      "eval --est ../shared/data/ouster/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt --ref "
      "../shared/data/ouster/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt --trees x.csv");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--ref-trees"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace taiga
