// `taiga eval` and `taiga compare` as users run them: values, formats, plots and exit codes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/io/trajectory_io.hpp"

namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

using Result = taiga::test::TaigaResult;
using taiga::test::runTaiga;

// A curved 3D path of n poses at 10 Hz, shifted by `offset` (m); `scale` stretches positions.
taiga::Trajectory path(std::size_t n, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero(),
                       double scale = 1.0) {
  taiga::Trajectory t;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 0.02 * static_cast<double>(i);
    const Eigen::Vector3d p(30.0 * std::cos(a), 20.0 * std::sin(a), 2.0 * std::sin(2.0 * a));
    t.append(1000.0 + 0.1 * static_cast<double>(i),
             taiga::lie::SE3(taiga::lie::SO3::fromAxisAngle({0, 0, 1}, a), scale * p + offset));
  }
  return t;
}

struct Files {
  taiga::test::TempDir dir;
  fs::path ref, est;
  Files() : ref(dir.file("ref.tum")), est(dir.file("est.tum")) {
    taiga::io::writeTum(ref, path(300));
    taiga::io::writeTum(est, path(300, {1.0, 2.0, 2.0}));  // |offset| = 3 m
  }
};

TEST(EvalCli, ConstantOffsetIsThreeMetresUnalignedAndZeroAligned) {
  Files f;
  const Result none = runTaiga(
      "eval --est " + f.est.string() + " --ref " + f.ref.string() + " --align none --json", false);
  ASSERT_EQ(none.exit_code, 0) << none.output;
  const nlohmann::json j = nlohmann::json::parse(none.output);
  EXPECT_NEAR(j["ape"]["translation_m"]["rmse"].get<double>(), 3.0, 1e-9);
  EXPECT_NEAR(j["ape"]["rmse_per_axis_m"][2].get<double>(), 2.0, 1e-9);
  EXPECT_EQ(j["association"]["pairs"], 300);
  EXPECT_NEAR(j["rpe"][0]["translation_m"]["max"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(j["drift"]["drift_m"].get<double>(), 0.0, 1e-9);  // origin-aligned
  EXPECT_NEAR(j["distance"]["mean_m"].get<double>(), 3.0, 1e-9);

  const Result se3 =
      runTaiga("eval --est " + f.est.string() + " --ref " + f.ref.string() + " --json", false);
  ASSERT_EQ(se3.exit_code, 0) << se3.output;
  EXPECT_NEAR(nlohmann::json::parse(se3.output)["ape"]["translation_m"]["rmse"].get<double>(), 0.0,
              1e-9);

  const Result text = runTaiga("eval --est " + f.est.string() + " --ref " + f.ref.string() +
                               " --align none --rotation --distance");
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_THAT(text.output, HasSubstr("associated  300 pairs"));
  EXPECT_THAT(text.output, ::testing::ContainsRegex("APE translation \\(m\\) +300 +3\\.000000"));
  EXPECT_THAT(text.output, HasSubstr("APE rotation (deg)"));
  EXPECT_THAT(text.output, HasSubstr("[3.00, 3.10) m"));

  const Result long_delta = runTaiga(
      "eval --est " + f.est.string() + " --ref " + f.ref.string() + " --rpe-delta 500 --json",
      false);
  ASSERT_EQ(long_delta.exit_code, 0) << long_delta.output;
  const nlohmann::json rpe = nlohmann::json::parse(long_delta.output)["rpe"][0];
  EXPECT_EQ(rpe["pairs"], 0);
  EXPECT_TRUE(rpe["translation_m"]["rmse"].is_null());

  const Result markdown = runTaiga(
      "eval --est " + f.est.string() + " --ref " + f.ref.string() + " --align none --markdown",
      false);
  ASSERT_EQ(markdown.exit_code, 0);
  EXPECT_THAT(markdown.output, HasSubstr("| APE translation (m) | 300 | 3.000000 | 3.000000 |"));
}

TEST(EvalCli, OffsetToleranceAndSim3) {
  taiga::test::TempDir dir;
  const fs::path ref = dir.file("ref.tum"), est = dir.file("est.tum");
  taiga::io::writeTum(ref, path(200));
  taiga::Trajectory late;  // the estimate's clock 2.05 s ahead, positions at half scale
  for (const auto& p : path(200, Eigen::Vector3d::Zero(), 0.5)) late.append(p.t_s + 2.05, p.pose);
  taiga::io::writeTum(est, late);
  const std::string files = "eval --est " + est.string() + " --ref " + ref.string();
  const Result none = runTaiga(files);
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_THAT(none.output, HasSubstr("no matching time stamps"));
  EXPECT_THAT(none.output, HasSubstr(est.string()));

  const Result sim3 = runTaiga(files + " --t-offset -2.05 --align sim3 --json", false);
  ASSERT_EQ(sim3.exit_code, 0) << sim3.output;
  const nlohmann::json j = nlohmann::json::parse(sim3.output);
  EXPECT_EQ(j["association"]["pairs"], 200);
  EXPECT_NEAR(j["alignment"]["scale"].get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(j["ape"]["translation_m"]["rmse"].get<double>(), 0.0, 1e-9);
}

TEST(EvalCli, KittiFilesAndTheKittiErrorOfAOnePercentScaleError) {
  // 1000 m along x in 1 m steps, in KITTI format (times are line indices); the estimate is 1 %
  // too long. Each devkit segment spans L + 1 m, hence 1.0044 % rather than 1 % (metrics_test).
  taiga::test::TempDir dir;
  taiga::Trajectory ref, est;
  for (int i = 0; i <= 1000; ++i) {
    ref.append(i, taiga::lie::SE3(taiga::lie::SO3(), {1.0 * i, 0.0, 0.0}));
    est.append(i, taiga::lie::SE3(taiga::lie::SO3(), {1.01 * i, 0.0, 0.0}));
  }
  taiga::io::writeKitti(dir.file("ref.txt"), ref);
  taiga::io::writeKitti(dir.file("est.txt"), est);
  const Result r = runTaiga("eval --est " + dir.file("est.txt").string() + " --ref " +
                                dir.file("ref.txt").string() + " --align none --json",
                            false);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["association"]["pairs"], 1001);
  EXPECT_EQ(j["kitti"]["segments"], 440);
  EXPECT_NEAR(j["kitti"]["translation_error_percent"].get<double>(), 1.004358766233766, 1e-9);
  EXPECT_NEAR(j["drift"]["drift_m"].get<double>(), 10.0, 1e-9);  // 1010 m instead of 1000 m
  EXPECT_NEAR(j["drift"]["drift_percent"].get<double>(), 1.0, 1e-9);
}

TEST(EvalCli, TimingStatisticsFromACsv) {
  Files f;
  const fs::path timing = f.dir.write(
      "timing.csv", "t_s,register_ms,total_ms\n0,50,60\n0.1,90,100\n0.2,110,130\n0.3,70,90\n");
  const Result r = runTaiga("eval --est " + f.est.string() + " --ref " + f.ref.string() +
                                " --timing " + timing.string() + " --json",
                            false);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json t = nlohmann::json::parse(r.output)["timing"];
  EXPECT_EQ(t["scans"], 4);
  EXPECT_DOUBLE_EQ(t["stages"][1]["p95_ms"].get<double>(), 125.5);
  EXPECT_DOUBLE_EQ(t["share_over_period"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(t["real_time_factor"].get<double>(), 0.4 / 0.38);
}

TEST(EvalCli, BadInputExitsWithTwoAndNamesTheFileAndLine) {
  Files f;
  const fs::path broken = f.dir.write("broken.tum", "0 0 0 0 0 0 0 1\n0.1 1 2 3 0 0 0\n");
  const Result r = runTaiga("eval --est " + broken.string() + " --ref " + f.ref.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr(broken.string() + ":2:"));
  const Result missing =
      runTaiga("eval --est " + f.dir.file("nope.tum").string() + " --ref " + f.ref.string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.output, HasSubstr("nope.tum"));
  const Result bad_timing =
      runTaiga("eval --est " + f.est.string() + " --ref " + f.ref.string() + " --timing " +
               f.dir.write("t.csv", "t_s,x_ms\n0,1\n").string());
  EXPECT_EQ(bad_timing.exit_code, 2);
  EXPECT_THAT(bad_timing.output, HasSubstr("t.csv:1: no total_ms column"));
  EXPECT_EQ(runTaiga("eval --est " + f.est.string() + " --ref " + f.ref.string() + " --rpe-delta 0")
                .exit_code,
            2);
  EXPECT_EQ(
      runTaiga("eval --est " + f.est.string() + " --ref " + f.ref.string() + " --align kabsch")
          .exit_code,
      2);
}

bool matplotlibInstalled() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' 2>/dev/null") == 0;
}

bool isPng(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::array<char, 8> magic{};
  in.read(magic.data(), magic.size());
  return in && std::string(magic.data() + 1, 3) == "PNG" && fs::file_size(file) > 10000;
}

TEST(EvalCli, PlotsArePngFiles) {
  if (!matplotlibInstalled()) GTEST_SKIP() << "python3-matplotlib is not installed";
  Files f;
  const fs::path timing =
      f.dir.write("timing.csv", "t_s,register_ms,total_ms\n0,50,60\n0.1,90,100\n");
  const fs::path plots = f.dir.file("plots");
  const Result r = runTaiga("eval --est " + f.est.string() + " --ref " + f.ref.string() +
                            " --timing " + timing.string() + " --plots " + plots.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* name : {"trajectory_top.png", "ape.png", "timing.png"}) {
    EXPECT_TRUE(isPng(plots / name)) << name;
    EXPECT_THAT(r.output, HasSubstr((plots / name).string()));
  }
}

TEST(EvalCli, MissingMatplotlibIsAClearErrorNotACrash) {
  Files f;
  // A module named matplotlib that fails to import stands in for the missing package.
  const fs::path fake = f.dir.file("fake");
  fs::create_directories(fake / "matplotlib");
  f.dir.write("fake/matplotlib/__init__.py", "raise ImportError('no matplotlib here')\n");
  const Result r = runTaiga("eval --est " + f.est.string() + " --ref " + f.ref.string() +
                                " --plots " + f.dir.file("plots").string(),
                            true, "PYTHONPATH=" + fake.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("python3-matplotlib is not installed"));
  EXPECT_THAT(r.output, HasSubstr("APE translation (m)"));  // the numbers are still printed
}

TEST(CompareCli, OneRowPerRunAndAnOverlayPlot) {
  taiga::test::TempDir dir;
  const fs::path ref = dir.file("ref.tum");
  taiga::io::writeTum(ref, path(300));
  fs::create_directories(dir.file("good"));
  fs::create_directories(dir.file("shifted/"));
  taiga::io::writeTum(dir.file("good") / "trajectory.tum", path(300));
  taiga::io::writeTum(dir.file("shifted") / "trajectory.tum", path(300, {0.0, 0.0, 0.5}));
  dir.write("good/timing.csv", "t_s,total_ms\n0,40\n0.1,60\n");
  const Result json =
      runTaiga("compare " + dir.file("good").string() + " " + dir.file("shifted").string() +
                   "/ --ref " + ref.string() + " --align none --json",
               false);
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const nlohmann::json j = nlohmann::json::parse(json.output);
  ASSERT_EQ(j["runs"].size(), 2u);
  EXPECT_EQ(j["runs"][0]["name"], "good");
  EXPECT_EQ(j["runs"][1]["name"], "shifted");
  EXPECT_NEAR(j["runs"][0]["ape_translation_m"]["rmse"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(j["runs"][1]["ape_translation_m"]["rmse"].get<double>(), 0.5, 1e-9);
  EXPECT_DOUBLE_EQ(j["runs"][0]["timing"]["stages"][0]["mean_ms"].get<double>(), 50.0);
  EXPECT_TRUE(j["runs"][1]["timing"].is_null());

  const Result text =
      runTaiga("compare " + dir.file("good").string() + " " + dir.file("shifted").string() +
               " --ref " + ref.string() + " --align none");
  ASSERT_EQ(text.exit_code, 0) << text.output;
  EXPECT_THAT(text.output, ::testing::ContainsRegex("shifted +300 +0\\.500000"));

  const Result no_run =
      runTaiga("compare " + dir.file("nothing").string() + " --ref " + ref.string());
  EXPECT_EQ(no_run.exit_code, 2);
  EXPECT_THAT(no_run.output, HasSubstr("nothing: not a directory"));

  if (!matplotlibInstalled()) return;
  const Result plot =
      runTaiga("compare " + dir.file("good").string() + " " + dir.file("shifted").string() +
               " --ref " + ref.string() + " --plots " + dir.file("plots").string());
  ASSERT_EQ(plot.exit_code, 0) << plot.output;
  EXPECT_TRUE(isPng(dir.file("plots") / "compare_top.png"));
  EXPECT_TRUE(isPng(dir.file("plots") / "compare_ape.png"));
}

}  // namespace
