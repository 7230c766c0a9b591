#include "taiga/io/trajectory_io.hpp"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/lie_test_support.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

using test::messageOf;
using ::testing::HasSubstr;

Trajectory randomTrajectory(int count) {
  test::RandomLie rng(7);
  Trajectory trajectory;
  // Times like a real recording's: large epoch seconds with sub-microsecond digits.
  for (int i = 0; i < count; ++i)
    trajectory.append(1700000000.123456789 + 0.1 * i + 1e-7 * i, rng.se3());
  return trajectory;
}

void expectBitIdentical(const Trajectory& a, const Trajectory& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].t_s, b[i].t_s);
    EXPECT_EQ(a[i].pose.translation(), b[i].pose.translation());
    EXPECT_EQ(a[i].pose.rotation().quaternion().coeffs(),
              b[i].pose.rotation().quaternion().coeffs());
  }
}

TEST(TrajectoryIo, TumRoundTripIsBitExact) {
  test::TempDir dir;
  const Trajectory written = randomTrajectory(50);
  writeTum(dir.file("t.tum"), written);
  expectBitIdentical(written, readTum(dir.file("t.tum")));
  EXPECT_EQ(detectTrajectoryFormat(dir.file("t.tum")), TrajectoryFormat::kTum);
}

TEST(TrajectoryIo, KittiRoundTripKeepsPosesAndTakesTimesFromAFile) {
  test::TempDir dir;
  const Trajectory written = randomTrajectory(20);
  writeKitti(dir.file("poses.txt"), written);
  const Trajectory by_index = readKitti(dir.file("poses.txt"));
  ASSERT_EQ(by_index.size(), written.size());
  EXPECT_EQ(by_index[3].t_s, 3.0);
  for (std::size_t i = 0; i < written.size(); ++i) {
    EXPECT_TRUE(by_index[i].pose.matrix().isApprox(written[i].pose.matrix(), 1e-15));
  }
  std::string times;
  for (const StampedPose& p : written) times += fmt::format("{}\n", p.t_s);
  const Trajectory timed = readKitti(dir.file("poses.txt"), dir.write("times.txt", times));
  EXPECT_EQ(timed[7].t_s, written[7].t_s);
  EXPECT_EQ(detectTrajectoryFormat(dir.file("poses.txt")), TrajectoryFormat::kKitti);
}

TEST(TrajectoryIo, AcceptsCommentsBlankLinesTabsAndCrlf) {
  test::TempDir dir;
  const auto path =
      dir.write("t.tum", "# header\n\n1.0 0 0 0 0 0 0 1\r\n  2.0\t1 +2 3 0 0 0 1\n# end\n");
  const Trajectory trajectory = readTrajectory(path);
  ASSERT_EQ(trajectory.size(), 2u);
  EXPECT_EQ(trajectory[1].pose.translation(), Eigen::Vector3d(1, 2, 3));
}

struct BadTum {
  const char* content;
  const char* message;
};

class TumRejects : public ::testing::TestWithParam<BadTum> {};

TEST_P(TumRejects, WithFileLineAndReason) {
  test::TempDir dir;
  const auto path = dir.write("bad.tum", GetParam().content);
  const std::string message = messageOf<InputError>([&] { readTum(path); });
  EXPECT_THAT(message, HasSubstr(path.string() + ":"));
  EXPECT_THAT(message, HasSubstr(GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    MalformedLines, TumRejects,
    ::testing::Values(
        BadTum{"1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n",
               ":2: expected 8 values (t x y z qx qy qz qw), found 7"},
        BadTum{"1 0 0 0 0 0 0 1 5\n", ":1: expected 8 values (t x y z qx qy qz qw), found 9"},
        BadTum{"# c\n1 0 zero 0 0 0 0 1\n", ":2: value 3 'zero' is not a number"},
        BadTum{"1 0 0 nan 0 0 0 1\n", ":1: value 4 'nan' is not a finite number"},
        BadTum{"1 0 0 inf 0 0 0 1\n", ":1: value 4 'inf' is not a finite number"},
        BadTum{"1,0,0,0,0,0,0,1\n", ":1: value 1 '1,0,0,0,0,0,0,1' contains a comma"},
        BadTum{"1 0 0 0 0 0 0 0\n", ":1: quaternion (qx qy qz qw) = (0 0 0 0) has norm 0.000000"},
        BadTum{"1 0 0 0 0 0 0.5 0.5\n", "expected a unit quaternion with w last"},
        BadTum{"1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n",
               ":2: time 1 is not after the previous pose's time 1"},
        BadTum{"2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n", ":2: time 1 is not after"},
        BadTum{"1 0 0 0 0 0 0 1e999\n", ":1: value 8 '1e999' is out of the range of a double"},
        BadTum{"", ": contains no poses"}, BadTum{"# only a comment\n", ": contains no poses"}));

TEST(TrajectoryIo, RejectsMissingFilesAndDirectories) {
  test::TempDir dir;
  EXPECT_THAT(messageOf<InputError>([&] { readTum(dir.file("missing.tum")); }),
              HasSubstr("missing.tum: cannot open: No such file or directory"));
  EXPECT_THAT(messageOf<InputError>([&] { readTum(dir.path()); }), HasSubstr("is a directory"));
  EXPECT_THAT(messageOf<InputError>([&] { writeTum(dir.file("no/such/dir.tum"), Trajectory()); }),
              HasSubstr("cannot open for writing"));
}

TEST(TrajectoryIo, KittiRejectsNonRotationsAndMismatchedTimes) {
  test::TempDir dir;
  const auto scaled = dir.write("scaled.txt", "2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(messageOf<InputError>([&] { readKitti(scaled); }),
              HasSubstr("scaled.txt:1: the 3x3 block is not a rotation matrix"));
  const auto mirrored = dir.write("mirror.txt", "-1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(messageOf<InputError>([&] { readKitti(mirrored); }), HasSubstr("det = -1.0000"));
  const auto poses = dir.write("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(messageOf<InputError>([&] { readKitti(poses, dir.write("few.txt", "0.0\n")); }),
              HasSubstr("few.txt: has fewer times than"));
  EXPECT_THAT(messageOf<InputError>([&] { readKitti(poses, dir.write("many.txt", "0\n1\n2\n")); }),
              HasSubstr("many.txt:3: more times than"));
  EXPECT_THAT(messageOf<InputError>([&] { readKitti(poses, dir.write("two.txt", "0 1\n1\n")); }),
              HasSubstr("two.txt:1: expected 1 value (time), found 2"));
  EXPECT_THAT(messageOf<InputError>([&] { readTrajectory(dir.write("odd.txt", "1 2 3\n")); }),
              HasSubstr("odd.txt:1: found 3 values; expected 8 (TUM"));
}

TEST(TrajectoryIo, AFullDiskIsSaidWithTheFile) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  EXPECT_THAT(messageOf<InputError>([&] { writeTum("/dev/full", randomTrajectory(10)); }),
              HasSubstr("/dev/full: write failed: No space left on device"));
}

}  // namespace
}  // namespace taiga::io
