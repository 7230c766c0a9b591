#include "taiga/preprocess/crop.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace taiga::preprocess
