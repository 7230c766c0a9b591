// Incremental voxel means: the same means as VoxelStatistics bit for bit, exact removal, and
// the table order that only the sequence of adds and removes decides.
#include "taiga/registration/voxel_means.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration {
namespace {

std::vector<Eigen::Vector3d> randomPoints(std::size_t n, unsigned seed, double extent_m) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-extent_m, extent_m);
  std::vector<Eigen::Vector3d> out(n);
  for (auto& p : out) p = {u(rng), u(rng), 0.2 * u(rng)};
  return out;
}

TEST(VoxelMeans, TheMeansOfVoxelStatisticsBitForBitAndRemovedExactly) {
  const auto a = randomPoints(20000, 3, 10.0);
  const auto b = randomPoints(5000, 4, 12.0);
  VoxelMeans means(0.2), only_a(0.2);
  VoxelStatistics statistics(0.2);
  means.add(a);
  means.add(b);
  statistics.add(a);
  statistics.add(b);
  only_a.add(a);
  // moments() lists the cells in key order, as means() does.
  const std::vector<CellMoments> moments = statistics.moments();
  const std::vector<Eigen::Vector3d> by_key = means.means();
  ASSERT_EQ(by_key.size(), moments.size());
  for (std::size_t i = 0; i < moments.size(); ++i) EXPECT_EQ(by_key[i], moments[i].mean);
  EXPECT_EQ(means.numPoints(), a.size() + b.size());
  EXPECT_GT(means.numCells(), 1000u);
  // Removing b leaves a's means, in the same table order as never having added b when the
  // sequences agree: only_a's.
  means.remove(b);
  std::vector<Eigen::Vector3d> left = means.meansInTableOrder(),
                               expected = only_a.meansInTableOrder();
  ASSERT_EQ(left.size(), expected.size());
  auto by_x = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
    return std::tie(p.x(), p.y(), p.z()) < std::tie(q.x(), q.y(), q.z());
  };
  std::sort(left.begin(), left.end(), by_x);
  std::sort(expected.begin(), expected.end(), by_x);
  EXPECT_EQ(left, expected);
  means.remove(a);
  EXPECT_EQ(means.numCells(), 0u);
  EXPECT_THROW(means.remove(a), std::logic_error);
}

TEST(VoxelMeans, SkipsPointsWithoutACellAndRejectsABadResolution) {
  VoxelMeans means(0.5);
  means.add(
      std::vector<Eigen::Vector3d>{{std::nan(""), 0.0, 0.0}, {0.1, 0.1, 0.1}, {1e9, 0.0, 0.0}});
  EXPECT_EQ(means.numSkipped(), 2u);
  EXPECT_EQ(means.numPoints(), 1u);
  EXPECT_THROW(VoxelMeans(0.0), std::invalid_argument);
  EXPECT_THROW(VoxelMeans(std::nan("")), std::invalid_argument);
}

TEST(VoxelMeans, DownsampleKeepsOnePointPerCell) {
  const std::vector<Eigen::Vector3d> p = {
      {0.1, 0.1, 0.1}, {0.3, 0.3, 0.3}, {1.5, 0.1, 0.1}, {std::nan(""), 0.0, 0.0}};
  const auto down = voxelDownsample(p, 1.0);
  ASSERT_EQ(down.size(), 2u);
  EXPECT_NEAR(down[0].x(), 0.2, 1e-5);
  EXPECT_NEAR(down[1].x(), 1.5, 1e-5);
}

}  // namespace
}  // namespace taiga::registration
