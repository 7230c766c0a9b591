#include "taiga/core/point_cloud.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace taiga {
namespace {

PointCloud makeCloud(int n, double t0) {
  PointCloud cloud;
  for (int i = 0; i < n; ++i) {
    cloud.positions.emplace_back(i, 2.0 * i, -i);
    cloud.times_s.push_back(t0 + 0.01 * i);
    cloud.rings.push_back(static_cast<std::uint16_t>(i % 4));
  }
  return cloud;
}

TEST(PointCloud, KeepWhereCompactsEveryChannelInOrder) {
  PointCloud cloud = makeCloud(6, 10.0);
  cloud.intensities = {0, 1, 2, 3, 4, 5};
  const PointCloud expected = cloud.select(std::vector<std::size_t>{1, 2, 5});
  cloud.keepWhere(std::vector<std::uint8_t>{0, 1, 1, 0, 0, 1});
  EXPECT_TRUE(cloud.isConsistent());
  EXPECT_EQ(cloud.positions, expected.positions);
  EXPECT_EQ(cloud.times_s, expected.times_s);
  EXPECT_EQ(cloud.intensities, expected.intensities);
  EXPECT_EQ(cloud.rings, expected.rings);
  EXPECT_TRUE(cloud.columns.empty());  // absent channels stay absent
}

TEST(PointCloud, ChannelsAreOptionalButMustMatchTheSize) {
  PointCloud cloud = makeCloud(5, 0.0);
  EXPECT_TRUE(cloud.isConsistent());
  EXPECT_TRUE(cloud.hasTimes());
  EXPECT_TRUE(cloud.hasRings());
  EXPECT_FALSE(cloud.hasIntensities());
  EXPECT_FALSE(cloud.hasColumns());
  cloud.intensities.push_back(1.0f);
  EXPECT_FALSE(cloud.isConsistent());
}

TEST(PointCloud, SelectKeepsEveryChannelInOrder) {
  const PointCloud cloud = makeCloud(6, 10.0);
  const std::vector<std::size_t> indices{4, 1};
  const PointCloud picked = cloud.select(indices);
  ASSERT_EQ(picked.size(), 2u);
  EXPECT_TRUE(picked.isConsistent());
  EXPECT_EQ(picked.positions[0], cloud.positions[4]);
  EXPECT_DOUBLE_EQ(picked.times_s[1], 10.01);
  EXPECT_EQ(picked.rings[0], 0);
  EXPECT_FALSE(picked.hasIntensities());
}

TEST(PointCloud, AppendRequiresTheSameChannels) {
  PointCloud cloud = makeCloud(3, 0.0);
  cloud.append(makeCloud(2, 5.0));
  EXPECT_EQ(cloud.size(), 5u);
  EXPECT_TRUE(cloud.isConsistent());
  EXPECT_EQ(cloud.timeSpan(), std::make_pair(0.0, 5.01));

  PointCloud without_times;
  without_times.positions.emplace_back(0, 0, 0);
  EXPECT_THROW(cloud.append(without_times), std::invalid_argument);

  PointCloud empty;
  empty.append(cloud);
  EXPECT_EQ(empty.size(), 5u);
}

}  // namespace
}  // namespace taiga
