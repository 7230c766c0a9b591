// OdometryCorrection on synthetic keyframes: the map->odom correction taken from a graph
// snapshot, reduced to a turn about z with an IMU, and a local-map rebuild only when the graph
// bent the local map's keyframes.
#include "../../src/pipeline/odometry_correction.hpp"

#include <gtest/gtest.h>

#include "taiga/core/angles.hpp"

namespace taiga::pipeline {
namespace {

lie::SE3 poseAt(double x_m, double yaw_rad) {
  return lie::SE3(lie::SO3::fromRollPitchYaw(0.0, 0.0, yaw_rad),
                  Eigen::Vector3d(x_m, 0.5 * x_m, 0.0));
}

struct Fixture {
  Odometry odometry{OdometryConfig{}, RigConfig{}, /*lidar_only=*/true};  // empty local map
  OdometryCorrection correction{4};
  std::vector<lie::SE3> T_odom_keyframes;

  explicit Fixture(int keyframes) {
    for (int k = 0; k < keyframes; ++k) {
      T_odom_keyframes.push_back(poseAt(1.0 * k, 0.05 * k));
      correction.addKeyframe(static_cast<std::uint64_t>(k), T_odom_keyframes.back());
    }
  }
  /// The graph's poses of keyframes k - count + 1 ... k, each T_map_odom_i * T_odom_i.
  mapping::GraphSnapshot snapshot(std::size_t k, std::size_t count,
                                  const std::function<lie::SE3(std::size_t)>& T_map_odom_at) {
    mapping::GraphSnapshot s{.keyframe = k};
    for (std::size_t i = k + 1 - count; i <= k; ++i)
      s.poses_T_map_body.push_back(T_map_odom_at(i) * T_odom_keyframes[i]);
    return s;
  }
};

TEST(OdometryCorrection, ARigidCorrectionMovesOnlyTheMapToOdomTransform) {
  Fixture f(6);
  EXPECT_TRUE(f.correction.T_map_odom().matrix().isIdentity());
  const lie::SE3 T_map_odom(lie::SO3::fromRollPitchYaw(0.0, 0.0, 0.1),
                            Eigen::Vector3d(0.3, -0.2, 0.05));
  const bool rebuilt = f.correction.apply(f.snapshot(3, 4, [&](std::size_t) { return T_map_odom; }),
                                          /*keep_gravity=*/false, f.odometry);
  EXPECT_FALSE(rebuilt);
  EXPECT_TRUE(f.correction.T_map_odom().matrix().isApprox(T_map_odom.matrix(), 1e-12));
}

TEST(OdometryCorrection,
     WithAnImuTheCorrectionIsATurnAboutZThatKeepsTheKeyframeWhereTheGraphHasIt) {
  Fixture f(6);
  // A correction with some tilt, as a graph without gravity could give.
  const lie::SE3 T_map_odom(lie::SO3::fromRollPitchYaw(0.02, -0.01, 0.1),
                            Eigen::Vector3d(0.3, -0.2, 0.05));
  f.correction.apply(f.snapshot(3, 4, [&](std::size_t) { return T_map_odom; }),
                     /*keep_gravity=*/true, f.odometry);
  const lie::SE3& corrected = f.correction.T_map_odom();
  const Eigen::Vector3d z_odom_in_map = corrected.rotation() * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(z_odom_in_map.z(), 1.0,
              1e-12);  // no tilt: the published roll and pitch stay the IMU's
  EXPECT_NEAR(corrected.rotation().yaw(), T_map_odom.rotation().yaw(), 1e-12);
  // Keyframe 3's position goes where the graph has it.
  const Eigen::Vector3d p_odom_3 = f.T_odom_keyframes[3].translation();
  EXPECT_LT((corrected * p_odom_3 - T_map_odom * p_odom_3).norm(), 1e-12);
}

TEST(OdometryCorrection, RebuildsTheLocalMapOnlyWhenTheGraphBentIt) {
  Fixture f(6);
  // Keyframe 2 moved 1 mm against the others: below kMinShiftM, no rebuild.
  auto bentBy = [](double shift_m) {
    return [shift_m](std::size_t i) {
      return i == 2 ? lie::SE3(lie::SO3(), Eigen::Vector3d(shift_m, 0.0, 0.0)) : lie::SE3();
    };
  };
  EXPECT_FALSE(f.correction.apply(f.snapshot(3, 4, bentBy(0.001)), false, f.odometry));
  // 10 cm: a loop bent the local map.
  EXPECT_TRUE(f.correction.apply(f.snapshot(4, 4, bentBy(0.10)), false, f.odometry));
  // The same shape again: the local map already has it.
  EXPECT_FALSE(f.correction.apply(f.snapshot(5, 4, bentBy(0.10)), false, f.odometry));
}

TEST(OdometryCorrection, ASnapshotOfUnknownKeyframesIsALogicError) {
  Fixture f(3);
  const mapping::GraphSnapshot of_keyframe_7{.keyframe = 7, .poses_T_map_body = {lie::SE3()}};
  EXPECT_THROW(f.correction.apply(of_keyframe_7, false, f.odometry), std::logic_error);
}

}  // namespace
}  // namespace taiga::pipeline
