// `taiga trees` on the map of a simulated handheld walk, scored against the simulator's trees.csv
// with the rig a user would write (rig.yaml, 64 beams). Seeds 12 and 13 make the table in
// BENCHMARK.md; this one is not among them.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"

namespace taiga {
namespace {

TEST(TreesScenario, AHandheldWalkFindsTheStemsAndTheirDbh) {
  test::TempDir dir;
  const std::string rec = dir.file("rec").string(), run = dir.file("run").string();
  auto r = test::runTaiga("simulate --scenario handheld-loop --duration 40 --seed 21 --beams 64 "
                          "--out " + rec);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::runTaiga("run " + rec + "/recording.bag --config " + rec + "/rig.yaml --out " + run);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::runTaiga("trees " + run);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::runTaiga("eval --est " + run + "/trajectory.tum --ref " + rec +
                         "/groundtruth.tum --trees " + run + "/trees.csv --ref-trees " + rec +
                         "/trees.csv --json",
                     false);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto trees = nlohmann::json::parse(r.output)["trees"];
  SCOPED_TRACE(trees.dump());
  EXPECT_GT(trees["reference"].get<int>(), 60);
  // Measured 97-98 % detection, 0-2 % commission, DBH RMSE 2.2-2.9 cm (bias -1.0 to -1.7 cm: the
  // lidar map's stems are slimmer than the true ones, docs/trees.md), position RMSE 1.8-2.3 cm.
  EXPECT_GE(trees["recall"].get<double>(), 0.92);
  EXPECT_LE(trees["commission"].get<double>(), 0.05);
  EXPECT_LE(trees["dbh_rmse_m"].get<double>(), 0.035);
  EXPECT_LE(std::abs(trees["dbh_bias_m"].get<double>()), 0.025);
  EXPECT_LE(trees["position_rmse_m"].get<double>(), 0.04);
  EXPECT_LE(trees["height_rmse_m"].get<double>(), 4.0);
}

}  // namespace
}  // namespace taiga
