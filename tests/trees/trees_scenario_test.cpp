// `taiga trees` on the map of a simulated handheld walk, scored against the simulator's trees.csv
// with the rig a user would write (rig.yaml, 64 beams). Seeds 12 and 13 make the table in
// BENCHMARK.md; this one is not among them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/trees/tree_files.hpp"

namespace taiga {
namespace {

TEST(TreesScenario, AHandheldWalkFindsTheStemsAndTheirDbhOnlineAsOffline) {
  test::TempDir dir;
  const std::string rec = dir.file("rec").string(), run = dir.file("run").string();
  auto r = test::runTaiga(
      "simulate --scenario handheld-loop --duration 40 --seed 21 --beams 64 "
      "--out " +
      rec);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The rig a user would write, with the online tree map on (mapping.trees).
  std::ifstream rig_in(rec + "/rig.yaml");
  std::string rig((std::istreambuf_iterator<char>(rig_in)), {});
  const std::string off = "\n  trees: false";  // rig.yaml states every key of the mapping section
  const std::size_t at = rig.find(off);
  ASSERT_NE(at, std::string::npos);
  rig.replace(at, off.size(), "\n  trees: true");
  std::ofstream(dir.file("rig_trees.yaml")) << rig;
  r = test::runTaiga("run " + rec + "/recording.bag --config " +
                     dir.file("rig_trees.yaml").string() + " --out " + run);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_NE(r.output.find("stems in trees.csv"), std::string::npos) << r.output;
  // The run's trees.csv against `taiga trees` on its map.las.
  r = test::runTaiga("trees " + run + " --out " + dir.file("offline").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Every point of the run's map knows its keyframe: the DBH fit measures along the beams.
  EXPECT_NE(r.output.find("residuals along the beams for"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("across the surface (no sensor"), std::string::npos) << r.output;
  // Most stems keep the fit along the beams (184 of 212 on the 60 s walk of seed 12, session 44).
  const std::size_t kept_at = r.output.find("kept along the beams for ");
  ASSERT_NE(kept_at, std::string::npos) << r.output;
  int along = 0, stems = 0;
  ASSERT_EQ(
      std::sscanf(r.output.c_str() + kept_at, "kept along the beams for %d of %d", &along, &stems),
      2);
  EXPECT_GE(along, stems * 2 / 3) << r.output;
  const auto online = trees::readTreesCsv(run + "/trees.csv");
  const auto offline = trees::readTreesCsv(dir.file("offline/trees.csv"));
  // The final pass reads the keyframe store, `taiga trees` the decimated map.las: stems at the
  // edge of the checks (12-36 points) tip either way. Measured 173 online against 178 offline,
  // 175 against 182 since a failed along-beam fit falls back to the fit across (session 42).
  const double slack = 0.05 * static_cast<double>(offline.size());
  EXPECT_NEAR(static_cast<double>(online.size()), static_cast<double>(offline.size()), slack);
  // The bound (DBH RMSE <= 0.5 cm) on the stems whose DBH both fits know to 2.5 cm: a stem
  // seen over 70-100 deg with 10 points came out 7.4 cm offline and 18.4 cm online (1-sigma
  // 8.9 cm), which alone made the RMSE over all stems 0.83 cm (0.48 cm before the NDT change of
  // session 40; 0.03-0.05 cm on the others). Every stem must agree within 3x the two fits'
  // combined 1-sigma plus 0.5 cm. Since the sigma includes the view jackknife (session 44) fewer
  // stems claim 2.5 cm: 117 of 175 (their RMSE 0.09 cm); with the formal sigma alone over 4/5.
  double sq = 0.0;
  std::size_t matched = 0, certain = 0;
  for (const auto& a : offline)
    for (const auto& b : online)
      if ((a.bh_xy_m - b.bh_xy_m).norm() < 0.2) {
        const double difference_m = a.dbh_m - b.dbh_m;
        ++matched;
        EXPECT_LE(std::abs(difference_m), 3.0 * std::hypot(a.dbh_sigma_m, b.dbh_sigma_m) + 0.005)
            << "stem at " << a.bh_xy_m.transpose();
        if (a.dbh_sigma_m < 0.025 && b.dbh_sigma_m < 0.025) {
          sq += difference_m * difference_m;
          ++certain;
        }
        break;
      }
  EXPECT_GE(static_cast<double>(matched) + slack, static_cast<double>(offline.size()));
  EXPECT_GE(certain, matched * 3 / 5);
  EXPECT_LE(std::sqrt(sq / std::max<std::size_t>(1, certain)), 0.005);

  r = test::runTaiga("eval --est " + run + "/trajectory.tum --ref " + rec +
                         "/groundtruth.tum --trees " + run + "/trees.csv --ref-trees " + rec +
                         "/trees.csv --json",
                     false);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto trees = nlohmann::json::parse(r.output)["trees"];
  SCOPED_TRACE(trees.dump());
  EXPECT_GT(trees["reference"].get<int>(), 60);
  // Measured on this seed (session 42): detection 97.6 %, commission 0.8 %, DBH RMSE 1.76 cm,
  // bias -0.83 cm, position RMSE 1.5 cm; the fit across the surface alone (`taiga trees` on
  // map.las) 2.17 cm and -1.39 cm, and 2.2-2.9 cm, -1.0 to -1.7 cm on seeds 12 and 13.
  EXPECT_GE(trees["recall"].get<double>(), 0.92);
  EXPECT_LE(trees["commission"].get<double>(), 0.05);
  EXPECT_LE(trees["dbh_rmse_m"].get<double>(), 0.025);
  EXPECT_LE(std::abs(trees["dbh_bias_m"].get<double>()), 0.012);
  EXPECT_LE(trees["position_rmse_m"].get<double>(), 0.04);
  EXPECT_LE(trees["height_rmse_m"].get<double>(), 4.0);
  // The stated DBH sigma: 73 % of the errors within 2 sigma (session 44; the formal sigma alone
  // covered 26-36 % on seeds 12 and 13); 55 % since session 49 (the odometry estimates its frame's
  // tilt: DBH RMSE 1.61 cm, bias -1.09 cm on this map). Not 95 %: the map's shrink (issue 25)
  // biases every stem alike, which no resampling of one stem's points can see (docs/trees.md,
  // "DBH sigma").
  EXPECT_GE(trees["dbh_within_2_sigma"].get<double>(), 0.5);
}

}  // namespace
}  // namespace taiga
