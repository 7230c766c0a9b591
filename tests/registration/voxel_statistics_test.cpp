// Incremental voxel statistics and means: exact add/remove, order independence, moments against
// a direct computation, the NDT target built from a map that had a keyframe added and removed,
// and VoxelMeans' means against VoxelStatistics' bit for bit.
#include "taiga/registration/voxel_statistics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "taiga/registration/ndt.hpp"
#include "taiga/registration/voxel_means.hpp"

namespace taiga::registration {
namespace {

std::vector<Eigen::Vector3d> randomPoints(std::size_t n, unsigned seed, double extent_m) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-extent_m, extent_m);
  std::vector<Eigen::Vector3d> out(n);
  for (auto& p : out) p = {u(rng), u(rng), 0.2 * u(rng)};
  return out;
}

TEST(VoxelStatistics, AddThenRemoveEqualsNeverAdded) {
  const auto a = randomPoints(20000, 1, 10.0);
  const auto b = randomPoints(5000, 2, 12.0);
  VoxelStatistics only_a(1.0);
  only_a.add(a);
  VoxelStatistics map(1.0);
  map.add(a);
  map.add(b);
  EXPECT_FALSE(map == only_a);
  map.remove(b);
  EXPECT_TRUE(map == only_a);
  EXPECT_EQ(map.numPoints(), a.size());
  EXPECT_EQ(map.numCells(), only_a.numCells());

  // The NDT target built from the map is the same, cell for cell and bit for bit.
  const NdtTarget from_map(map);
  const NdtTarget from_a(only_a);
  ASSERT_EQ(from_map.cells().size(), from_a.cells().size());
  ASSERT_GT(from_a.cells().size(), 100u);
  for (std::size_t i = 0; i < from_a.cells().size(); ++i) {
    EXPECT_EQ(from_map.cells()[i].mean, from_a.cells()[i].mean);
    EXPECT_EQ(from_map.cells()[i].inverse_covariance, from_a.cells()[i].inverse_covariance);
  }
}

TEST(VoxelStatistics, PointsAddedWithTheirBeamsAreRemovedExactly) {
  const auto a = randomPoints(20000, 5, 10.0);
  const auto b = randomPoints(5000, 6, 12.0);
  const BeamNoise from_a{{0.3, -0.2, 1.0}, 0.01, 0.0005}, from_b{{5.0, 2.0, 1.5}, 0.02, 0.001};
  VoxelStatistics only_a(0.5, true);
  only_a.add(a, from_a);
  VoxelStatistics map(0.5, true);
  map.add(a, from_a);
  map.add(b, from_b);
  EXPECT_FALSE(map == only_a);
  map.remove(b, from_b);
  EXPECT_TRUE(map == only_a);
  // The beams are the noise's share only: the moments themselves are those of the points.
  VoxelStatistics without_beams(0.5, true);
  without_beams.add(a);
  const std::vector<CellMoments> with = only_a.moments(), without = without_beams.moments();
  ASSERT_EQ(with.size(), without.size());
  int with_noise_share = 0;
  for (std::size_t i = 0; i < with.size(); ++i) {
    EXPECT_EQ(with[i].covariance, without[i].covariance);
    EXPECT_EQ(with[i].ww, without[i].ww);
    EXPECT_TRUE(without[i].noise_xx.isZero());
    if (with[i].count >= 2 && with[i].noise_xx.trace() > 0.0) ++with_noise_share;
  }
  EXPECT_GT(with_noise_share, 100);

  // 2 m cells and a 0.5 m noise: shares beyond 2^63 quanta^4, still exact.
  const BeamNoise loud{{0.0, 0.0, 0.0}, 0.5, 0.01};
  VoxelStatistics large_a(2.0, true), large(2.0, true);
  large_a.add(a, loud);
  large.add(a, loud);
  large.add(b, loud);
  large.remove(b, loud);
  EXPECT_TRUE(large == large_a);
}

TEST(VoxelStatistics, OrderOfAddingDoesNotMatter) {
  const auto a = randomPoints(3000, 3, 5.0);
  const auto b = randomPoints(3000, 4, 5.0);
  VoxelStatistics ab(0.5), ba(0.5);
  ab.add(a);
  ab.add(b);
  ba.add(b);
  ba.add(a);
  EXPECT_TRUE(ab == ba);
}

TEST(VoxelStatistics, MomentsMatchADirectComputation) {
  // Points in one 2 m cell, away from the origin as map coordinates are.
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 0.2);
  std::vector<Eigen::Vector3d> points;
  const Eigen::Vector3d centre(101.0, -47.0, 3.0);
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d p = centre + Eigen::Vector3d(n(rng), 0.5 * n(rng), 0.1 * n(rng));
    if (((p - centre).array().abs() < 0.99).all()) points.push_back(p);
  }
  VoxelStatistics stats(2.0);
  stats.add(points);
  ASSERT_EQ(stats.numCells(), 1u);
  const CellMoments m = stats.moments().front();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : points) cov += (p - mean) * (p - mean).transpose();
  cov /= static_cast<double>(points.size() - 1);
  EXPECT_EQ(m.count, points.size());
  EXPECT_LT((m.mean - mean).norm(), 1e-6);  // quantization is 10 um per point, averaged
  EXPECT_LT((m.covariance - cov).norm(), 1e-7);
  EXPECT_GT(cov.norm(), 1e-2);
}

TEST(VoxelStatistics, RemovingAPointThatWasNeverAddedThrows) {
  VoxelStatistics stats(1.0);
  const std::vector<Eigen::Vector3d> p = {{0.5, 0.5, 0.5}};
  EXPECT_THROW(stats.remove(p), std::logic_error);
  EXPECT_THROW(VoxelStatistics(0.0), std::invalid_argument);
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
