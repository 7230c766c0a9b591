// timing.csv reading and the processing time statistics.
#include "taiga/eval/timing.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::eval {
namespace {

using taiga::test::messageOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

const char* const kSmallCsv =
    "t_s,preprocess_ms,register_ms,total_ms\n"
    "0.0,10,50,60\n"
    "0.1,10,90,100\n"
    "# a comment line\n"
    "0.2,20,110,130\n"
    "0.3, 20 ,70,90\n";

TEST(Timing, StatisticsOfASmallTable) {
  taiga::test::TempDir dir;
  const TimingTable table = readTimingCsv(dir.write("timing.csv", kSmallCsv));
  EXPECT_THAT(table.columns, ElementsAre("preprocess_ms", "register_ms", "total_ms"));
  EXPECT_THAT(table.t_s, ElementsAre(0.0, 0.1, 0.2, 0.3));
  EXPECT_EQ(table.total_column, 2u);

  const TimingStatistics s = computeTimingStatistics(table, 0.1);
  EXPECT_EQ(s.scan_count, 4u);
  const StageTiming& total = s.total();
  EXPECT_EQ(total.name, "total_ms");
  EXPECT_DOUBLE_EQ(total.mean_ms, 95.0);
  EXPECT_DOUBLE_EQ(total.median_ms, 95.0);  // (90 + 100) / 2
  EXPECT_DOUBLE_EQ(total.p95_ms, 125.5);    // rank 2.85 between 100 and 130
  EXPECT_DOUBLE_EQ(total.max_ms, 130.0);
  EXPECT_DOUBLE_EQ(s.stages[0].mean_ms, 15.0);
  EXPECT_DOUBLE_EQ(s.stages[1].median_ms, 80.0);
  EXPECT_EQ(s.scans_over_period, 1u);  // 130 ms; 100 ms is not over the period
  EXPECT_DOUBLE_EQ(s.share_over_period, 0.25);
  EXPECT_DOUBLE_EQ(s.recording_duration_s, 0.4);  // 0.3 s between first and last, + one period
  EXPECT_DOUBLE_EQ(s.processing_s, 0.38);
  EXPECT_DOUBLE_EQ(s.real_time_factor, 0.4 / 0.38);

  const TimingStatistics slow = computeTimingStatistics(table, 0.05);
  EXPECT_EQ(slow.scans_over_period, 4u);
  EXPECT_THROW(computeTimingStatistics(table, 0.0), InputError);
}

TEST(Timing, MalformedFilesNameTheFileLineAndColumn) {
  taiga::test::TempDir dir;
  const auto no_total = dir.write("a.csv", "t_s,register_ms\n0,1\n");
  EXPECT_THAT(messageOf<InputError>([&] { readTimingCsv(no_total); }),
              HasSubstr(no_total.string() + ":1: no total_ms column"));
  const auto bad_first = dir.write("b.csv", "time,total_ms\n0,1\n");
  EXPECT_THAT(messageOf<InputError>([&] { readTimingCsv(bad_first); }),
              HasSubstr(":1: the first column is 'time', expected t_s"));
  const auto bad_value = dir.write("c.csv", "t_s,register_ms,total_ms\n0,1,2\n0.1,x,3\n");
  EXPECT_THAT(messageOf<InputError>([&] { readTimingCsv(bad_value); }),
              HasSubstr(bad_value.string() + ":3: register_ms: 'x' is not a finite number"));
  const auto short_row = dir.write("d.csv", "t_s,register_ms,total_ms\n0,1\n");
  EXPECT_THAT(messageOf<InputError>([&] { readTimingCsv(short_row); }),
              HasSubstr(":2: expected 3 values (t_s,register_ms,total_ms), found 2"));
  const auto negative = dir.write("e.csv", "t_s,total_ms\n0,-1\n");
  EXPECT_THAT(messageOf<InputError>([&] { readTimingCsv(negative); }),
              HasSubstr(":2: total_ms: -1 is negative"));
  const auto backwards = dir.write("f.csv", "t_s,total_ms\n1,1\n0.5,1\n");
  EXPECT_THAT(messageOf<InputError>([&] { readTimingCsv(backwards); }),
              HasSubstr(":3: t_s 0.5 is not after the previous row's 1"));
  const auto empty = dir.write("g.csv", "t_s,total_ms\n");
  EXPECT_THAT(messageOf<InputError>([&] { readTimingCsv(empty); }), HasSubstr("no data rows"));
  EXPECT_THAT(messageOf<InputError>([&] { readTimingCsv(dir.file("missing.csv")); }),
              HasSubstr("missing.csv: cannot open"));
}

}  // namespace
}  // namespace taiga::eval
