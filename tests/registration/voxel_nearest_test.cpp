// VoxelNearest gives the kd-tree's nearest distances bit for bit: for queries near and far, with
// and without hints, at cells smaller and larger than the radius, and the same agreement.
#include "taiga/registration/voxel_nearest.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "taiga/registration/kdtree.hpp"

namespace taiga::registration {
namespace {

/// Points on a few planes and "stems" around the origin (both signs of every axis), as a local
/// map holds them, plus scattered points.
std::vector<Eigen::Vector3d> mapPoints(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-12.0, 12.0), small(-0.02, 0.02);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 6000; ++i) points.emplace_back(u(rng), u(rng), -1.5 + small(rng));
  for (int stem = 0; stem < 12; ++stem) {
    const double cx = u(rng), cy = u(rng);
    for (int i = 0; i < 300; ++i) {
      const double angle = 0.021 * i, z = -1.5 + 0.01 * i;
      points.emplace_back(cx + 0.15 * std::cos(angle), cy + 0.15 * std::sin(angle), z);
    }
  }
  for (int i = 0; i < 500; ++i) points.emplace_back(u(rng), u(rng), u(rng) * 0.3);
  return points;
}

TEST(VoxelNearest, FindsTheKdTreesNearestDistanceBitForBit) {
  std::mt19937_64 rng(7);
  const std::vector<Eigen::Vector3d> points = mapPoints(rng);
  const KdTree tree(points);
  std::uniform_real_distribution<double> u(-16.0, 16.0);
  for (const double cell_m : {0.3, 0.5, 2.5}) {
    const VoxelNearest grid(points, cell_m);
    ASSERT_EQ(grid.size(), points.size());
    std::size_t found = 0, hinted_found = 0;
    std::size_t hint = VoxelNearest::kNoHint, tree_hint = KdTree::kNoHint;
    for (int q = 0; q < 3000; ++q) {
      const Eigen::Vector3d query(u(rng), u(rng), u(rng) * 0.2);
      for (const double radius_m : {0.3, 2.0, std::numeric_limits<double>::infinity()}) {
        std::size_t i_tree = 0, i_grid = 0;
        double d_tree = 0.0, d_grid = 0.0;
        const bool in_tree = tree.nearestWithin(query, radius_m, i_tree, d_tree);
        const bool in_grid = grid.nearestWithin(query, radius_m, i_grid, d_grid);
        ASSERT_EQ(in_tree, in_grid) << "cell " << cell_m << " radius " << radius_m;
        if (!in_tree) continue;
        ++found;
        EXPECT_EQ(d_tree, d_grid);  // exactly: the same point's distance, summed alike
        EXPECT_EQ(grid.points()[i_grid], tree.points()[i_tree]);
      }
      // Hints from the previous query, as agreement() gives them.
      std::size_t i_tree = 0, i_grid = 0;
      double d_tree = 0.0, d_grid = 0.0;
      const bool in_tree = tree.nearestWithin(query, 2.0, i_tree, d_tree, tree_hint);
      const bool in_grid = grid.nearestWithin(query, 2.0, i_grid, d_grid, hint);
      ASSERT_EQ(in_tree, in_grid);
      if (in_tree) {
        ++hinted_found;
        EXPECT_EQ(d_tree, d_grid);
        tree_hint = i_tree;
        hint = i_grid;
      }
    }
    // Both near and far queries were asked: some found nothing within the smallest radius.
    EXPECT_GT(found, 3000u);
    EXPECT_LT(found, 9000u);
    EXPECT_GT(hinted_found, 100u);
  }
}

TEST(VoxelNearest, AgreesWithTheKdTreesAgreement) {
  std::mt19937_64 rng(8);
  const std::vector<Eigen::Vector3d> points = mapPoints(rng);
  std::vector<Eigen::Vector3d> source(points.begin(), points.begin() + 4000);
  const lie::SE3 T(lie::SO3::fromAxisAngle(Eigen::Vector3d(0.2, -0.4, 1.0).normalized(), 0.05),
                   Eigen::Vector3d(0.3, -0.2, 0.1));
  const Agreement from_tree = agreement(source, KdTree(points), T, 0.5);
  const Agreement from_grid = agreement(source, VoxelNearest(points, 0.5), T, 0.5);
  EXPECT_EQ(from_tree.fitness_m2, from_grid.fitness_m2);
  EXPECT_EQ(from_tree.share, from_grid.share);
  EXPECT_GT(from_tree.share, 0.1);
  EXPECT_LT(from_tree.share, 1.0);
}

TEST(VoxelNearest, EmptyAndBadInput) {
  const VoxelNearest empty(std::vector<Eigen::Vector3d>{}, 0.5);
  std::size_t i = 0;
  double d = 0.0;
  EXPECT_FALSE(empty.nearestWithin(Eigen::Vector3d::Zero(), 10.0, i, d));
  EXPECT_THROW(VoxelNearest(std::vector<Eigen::Vector3d>{}, 0.0), std::invalid_argument);
  const VoxelNearest one(std::vector<Eigen::Vector3d>{{1.0, 2.0, 3.0}}, 0.5);
  EXPECT_FALSE(one.nearestWithin(Eigen::Vector3d(std::nan(""), 0.0, 0.0), 10.0, i, d));
  // Non-finite points are left out; points beyond the grid are refused, not dropped.
  const VoxelNearest with_nan(
      std::vector<Eigen::Vector3d>{{std::nan(""), 0.0, 0.0}, {1.0, 2.0, 3.0}}, 0.5);
  EXPECT_EQ(with_nan.size(), 1u);
  EXPECT_THROW(VoxelNearest(std::vector<Eigen::Vector3d>{{7.0e6, 0.0, 0.0}}, 1.0),
               std::invalid_argument);
  ASSERT_TRUE(one.nearestWithin(Eigen::Vector3d(-100.0, 2.0, 3.0), 200.0, i, d));
  EXPECT_EQ(d, 101.0 * 101.0);
}

}  // namespace
}  // namespace taiga::registration
