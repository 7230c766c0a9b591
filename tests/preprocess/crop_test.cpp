#include "taiga/preprocess/crop.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace taiga::preprocess {
namespace {

TEST(Crop, RemovesThePointsInsideAnyBoxAndKeepsOrderAndChannels) {
  PointCloud cloud;
  cloud.positions = {{0, 0, 0}, {5, 0, 0}, {0.5, 0.5, -0.5}, {-3, 2, 1}, {1, 1, 1}};
  cloud.intensities = {0, 1, 2, 3, 4};
  const std::vector<Box> boxes{{{-1, -1, -1}, {1, 1, 0}}, {{-4, 1, 0}, {-2, 3, 2}}};
  const PointCloud kept = removeInsideBoxes(cloud, boxes);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_FLOAT_EQ(kept.intensities[0], 1.0f);
  EXPECT_FLOAT_EQ(kept.intensities[1], 4.0f);  // (1,1,1) is above the first box's top at z = 0
}

TEST(Crop, KeepsTheRangeInterval) {
  PointCloud cloud;
  cloud.positions = {{0.2, 0, 0}, {0, 3, 0}, {0, 0, 80}, {1, 1, 1}};
  const PointCloud kept = keepRange(cloud, 0.5, 50.0);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_DOUBLE_EQ(kept.positions[0].y(), 3.0);
  EXPECT_DOUBLE_EQ(kept.positions[1].x(), 1.0);
}

TEST(Crop, RangeAndBoxesInOnePassAsOneAfterTheOther) {
  PointCloud cloud;
  for (int i = 0; i < 200; ++i) {
    cloud.positions.emplace_back(0.1 * i - 10.0, 0.05 * i - 3.0, 0.02 * i);
    cloud.times_s.push_back(i);
  }
  const std::vector<OrientedBox> boxes{
      OrientedBox::fromBox({{-2, -4, -1}, {1, 0, 5}}),
      {{5, 3, 2}, {1, 2, 1}, Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix()}};
  const PointCloud both = keepRangeOutsideBoxes(cloud, 1.0, 8.0, boxes);
  const PointCloud in_turn = removeInsideBoxes(keepRange(cloud, 1.0, 8.0), boxes);
  ASSERT_GT(both.size(), 20u);
  ASSERT_LT(both.size(), keepRange(cloud, 1.0, 8.0).size());  // the boxes took some
  EXPECT_EQ(both.positions, in_turn.positions);
  EXPECT_EQ(both.times_s, in_turn.times_s);
  EXPECT_EQ(keepRangeOutsideBoxes(cloud, 1.0, 8.0, {}).positions,
            keepRange(cloud, 1.0, 8.0).positions);
}

}  // namespace
}  // namespace taiga::preprocess
