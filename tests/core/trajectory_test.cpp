#include "taiga/core/trajectory.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/lie_test_support.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga {
namespace {

using test::messageOf;
using ::testing::HasSubstr;

// A screw motion X(t) = X0 * Exp(t * tau): SE(3) interpolation between any two of its samples
// reproduces it exactly.
lie::SE3 screw(double t) {
  static const lie::SE3 X0(lie::SO3::fromRollPitchYaw(0.1, -0.2, 1.0), Eigen::Vector3d(5, -2, 1));
  static const lie::Vector6 tau =
      lie::makeTangent(Eigen::Vector3d(1.0, 0.2, -0.1), Eigen::Vector3d(0.05, 0.1, 0.9));
  return X0.plus(t * tau);
}

Trajectory sampledScrew(double t0, double dt, int count) {
  Trajectory trajectory;
  for (int i = 0; i < count; ++i) trajectory.append(t0 + i * dt, screw(t0 + i * dt));
  return trajectory;
}

TEST(Trajectory, InterpolatesOnTheManifold) {
  const Trajectory trajectory = sampledScrew(100.0, 0.5, 9);
  for (double t : {100.0, 100.1, 101.25, 102.0, 103.99, 104.0}) {
    EXPECT_TRUE(trajectory.poseAt(t).matrix().isApprox(screw(t).matrix(), 1e-12)) << t;
  }
  // Exactly at a sample the sample itself comes back.
  EXPECT_TRUE(trajectory.poseAt(101.5).matrix().isApprox(trajectory[3].pose.matrix(), 1e-15));
}

TEST(Trajectory, ReportsTimesOutsideItsSpan) {
  const Trajectory trajectory = sampledScrew(10.0, 1.0, 3);
  EXPECT_TRUE(trajectory.covers(10.0));
  EXPECT_TRUE(trajectory.covers(12.0));
  EXPECT_FALSE(trajectory.covers(12.001));
  EXPECT_FALSE(trajectory.tryPoseAt(9.5).has_value());
  const std::string before = messageOf<OutOfRangeError>([&] { trajectory.poseAt(9.5); });
  EXPECT_THAT(before, HasSubstr("t = 9.500000 s"));
  EXPECT_THAT(before, HasSubstr("0.500000 s before the trajectory span [10.000000, 12.000000] s"));
  const std::string after = messageOf<OutOfRangeError>([&] { trajectory.poseAt(15.0); });
  EXPECT_THAT(after, HasSubstr("3.000000 s after"));
  EXPECT_THAT(messageOf<OutOfRangeError>([] { Trajectory().poseAt(1.0); }),
              HasSubstr("empty trajectory"));
}

TEST(Trajectory, RejectsTimesThatDoNotIncrease) {
  Trajectory trajectory = sampledScrew(0.0, 1.0, 2);
  EXPECT_THAT(
      messageOf<std::invalid_argument>([&] { trajectory.append(1.0, lie::SE3()); }),
      HasSubstr("pose 2 at t = 1.000000000 s is not after the previous pose at t = 1.000000000 s"));
  EXPECT_THAT(
      messageOf<std::invalid_argument>([&] { trajectory.append(std::nan(""), lie::SE3()); }),
      HasSubstr("non-finite time"));
  EXPECT_THROW(Trajectory({{1.0, lie::SE3()}, {0.5, lie::SE3()}}), std::invalid_argument);
}

TEST(Trajectory, PathLengthSumsTranslations) {
  Trajectory trajectory;
  trajectory.append(0.0, lie::SE3(lie::SO3(), Eigen::Vector3d(0, 0, 0)));
  trajectory.append(1.0, lie::SE3(lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), 1.0),
                                  Eigen::Vector3d(3, 4, 0)));
  trajectory.append(2.0, lie::SE3(lie::SO3(), Eigen::Vector3d(3, 4, 2)));
  EXPECT_DOUBLE_EQ(trajectory.pathLength(), 7.0);
  EXPECT_DOUBLE_EQ(Trajectory().pathLength(), 0.0);
}

}  // namespace
}  // namespace taiga
