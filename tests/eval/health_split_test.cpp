// The APE split by the health status of each pose's scan (health_split.hpp): scans.csv read with
// its quoted reasons (which hold commas), poses assigned to the first scan ending at or after
// them, and bad files named with the line.
#include "taiga/eval/health_split.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::eval {
namespace {

using ::testing::HasSubstr;

constexpr const char* kHeader =
    "t_s,scan,lidar_factor,fitness_m2,iterations,converged,inliers,hessian_condition,"
    "source_points,keyframe,note,status,health_reason,map_segment,innovation_m,innovation_deg\n";

std::string row(double t_s, const std::string& status, const std::string& reason) {
  return std::to_string(t_s) + ",0,used,0.01,5,1,100,10,200,0,\"a, note\"," + status + ",\"" +
         reason + "\",0,0.01,0.1\n";
}

TEST(HealthSplit, ReadsStatusesPastQuotedCommas) {
  const test::TempDir dir;
  const auto file = dir.write("scans.csv", std::string(kHeader) + row(1.0, "ok", "") +
                                               row(2.0, "degraded", "fitness 3, and more") +
                                               row(3.0, "lost", "no scan ok, for 1.1 s"));
  const std::vector<ScanStatusAt> scans = readScanStatuses(file);
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(scans[1].status, "degraded");
  EXPECT_EQ(scans[2].status, "lost");
  EXPECT_DOUBLE_EQ(scans[2].t_s, 3.0);
}

TEST(HealthSplit, GroupsEachPoseWithTheScanItLeadsUpTo) {
  EvalResult r;
  // Poses at 0.5, 1.0 (scan 1's end), 1.5 and 2.0 (scan 2), 2.5 (scan 3), 3.5 (after the last).
  for (double t : {0.5, 1.0, 1.5, 2.0, 2.5, 3.5}) r.pairs.est.push_back({t, lie::SE3()});
  r.ape.translation_error_m = {0.1, 0.1, 3.0, 4.0, 10.0, 99.0};
  const std::vector<StatusApe> split =
      apeByStatus(r, {{1.0, "ok"}, {2.0, "degraded"}, {3.0, "lost"}});
  ASSERT_EQ(split.size(), 3u);
  EXPECT_EQ(split[0].status, "ok");
  EXPECT_EQ(split[0].poses, 2u);
  EXPECT_NEAR(split[0].rmse_m, 0.1, 1e-12);
  EXPECT_EQ(split[1].poses, 2u);
  EXPECT_NEAR(split[1].rmse_m, std::sqrt((9.0 + 16.0) / 2.0), 1e-12);
  EXPECT_DOUBLE_EQ(split[1].max_m, 4.0);
  EXPECT_EQ(split[2].poses, 1u);  // 3.5 s lies after the last scan: left out
}

// The ok poses evaluated alone: a lost stretch far off pulls the alignment of all poses, so the ok
// poses look wrong among them; aligned on themselves they are exact.
TEST(HealthSplit, TheOkPosesAlignedAloneAreNotPulledByALostStretch) {
  Trajectory truth, estimate;
  std::vector<ScanStatusAt> scans;
  for (int k = 0; k < 40; ++k) {
    const double t_s = 0.1 * k;
    const lie::SE3 T(lie::SO3::fromRollPitchYaw(0.0, 0.0, 0.05 * k),
                     Eigen::Vector3d(k, 0.02 * k * k, 0.1 * std::sin(k)));
    truth.append(t_s, T);
    const bool lost = k >= 25 && k < 35;  // 10 poses 3 m off
    estimate.append(t_s, lost ? lie::SE3(lie::SO3(), Eigen::Vector3d(0, 3, 0)) * T : T);
    scans.push_back({t_s, lost ? "lost" : "ok"});
  }
  const Trajectory ok = posesWithStatus(estimate, scans, "ok");
  EXPECT_EQ(ok.size(), 30u);
  const std::vector<StatusApe> pulled = apeByStatus(evaluate(estimate, truth, {}), scans);
  ASSERT_EQ(pulled.front().status, "ok");
  EXPECT_GT(pulled.front().rmse_m, 0.1);
  EXPECT_LT(evaluate(ok, truth, {}).ape.translation_m.max, 1e-9);
  EXPECT_EQ(posesWithStatus(estimate, scans, "lost").size(), 10u);
}

TEST(HealthSplit, BadFilesAreNamedWithTheLine) {
  const test::TempDir dir;
  const auto old = dir.write("old.csv", "t_s,scan,lidar_factor\n1.0,0,used\n");
  EXPECT_THAT(test::messageOf<InputError>([&] { readScanStatuses(old); }),
              HasSubstr("old.csv:1: no column 'status'"));
  const auto bad =
      dir.write("bad.csv", std::string(kHeader) + row(1.0, "ok", "") +
                               "oops,0,used,0.01,5,1,100,10,200,0,\"\",ok,\"\",0,0,0\n");
  EXPECT_THAT(test::messageOf<InputError>([&] { readScanStatuses(bad); }),
              HasSubstr("bad.csv:3: column 't_s': expected a number, got 'oops'"));
  const auto short_row = dir.write("short.csv", std::string(kHeader) + "1.0,0,used\n");
  EXPECT_THAT(test::messageOf<InputError>([&] { readScanStatuses(short_row); }),
              HasSubstr("short.csv:2: 3 fields, the header has 16"));
  EXPECT_THAT(test::messageOf<InputError>([&] { readScanStatuses(dir.file("none.csv")); }),
              HasSubstr("none.csv: cannot open the scans file"));
}

}  // namespace
}  // namespace taiga::eval
