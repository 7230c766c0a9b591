#include "taiga/core/progress.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace taiga {
namespace {

using ::testing::HasSubstr;

std::string contentOf(std::FILE* file) {
  std::rewind(file);
  std::string text;
  for (int c; (c = std::fgetc(file)) != EOF;) text.push_back(static_cast<char>(c));
  return text;
}

TEST(Progress, FormatsDurations) {
  EXPECT_EQ(formatDuration(0.0), "0:00");
  EXPECT_EQ(formatDuration(65.4), "1:05");
  EXPECT_EQ(formatDuration(3723.0), "1:02:03");
  EXPECT_EQ(formatDuration(-1.0), "--:--");
  EXPECT_EQ(formatDuration(1.0 / 0.0), "--:--");
}

TEST(Progress, LineShowsRateElapsedAndRemaining) {
  // 250 of 1000 scans in 50 s: 5 scans/s, 750 scans left take 150 s.
  EXPECT_EQ(formatProgressLine("run", 250, 1000, "scans", 50.0),
            "run  250/1000 scans   25%  5.0 scans/s  elapsed 0:50  remaining 2:30");
  // Nothing done yet: the remaining time is unknown, not infinite or negative.
  EXPECT_THAT(formatProgressLine("run", 0, 10, "scans", 0.0), HasSubstr("remaining --:--"));
}

TEST(Progress, DrawsOnlyWhenEnabled) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  {
    Progress silent("run", 10, "scans", file, false);
    for (std::size_t i = 0; i <= 10; ++i) silent.update(i);
  }
  EXPECT_EQ(contentOf(file), "");
  {
    Progress shown("run", 10, "scans", file, true);
    shown.update(3);
    shown.finish();
  }
  const std::string text = contentOf(file);
  EXPECT_THAT(text, HasSubstr("\rrun  3/10 scans"));
  EXPECT_EQ(text.back(), '\n');
  std::fclose(file);
}

TEST(Progress, IsOffWhenTheOutputIsNotATerminal) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  EXPECT_FALSE(Progress("run", 10, "scans", file).enabled());
  std::fclose(file);
}

}  // namespace
}  // namespace taiga
