// The level-of-detail octree (view/lod_tree.hpp): every point in exactly one node, the coarse
// nodes an even subsample, the cubes nested, projected coordinates kept to the millimetre.
#include "taiga/view/lod_tree.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>

namespace taiga::view {
namespace {

/// A forest-like cloud: a 60 x 40 m ground and 30 stems 20 m tall, with intensities.
PointCloud forest(std::size_t points, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  PointCloud cloud;
  for (std::size_t i = 0; i < points; ++i) {
    Eigen::Vector3d p;
    if (i % 2 == 0) {
      p = {60.0 * u(rng), 40.0 * u(rng), 0.3 * u(rng)};
    } else {
      const int stem = static_cast<int>(i / 2 % 30);
      const double angle = 2.0 * M_PI * u(rng);
      p = {5.0 + 10.0 * (stem % 6) + 0.15 * std::cos(angle),
           5.0 + 8.0 * (stem / 6) + 0.15 * std::sin(angle), 20.0 * u(rng)};
    }
    cloud.positions.push_back(p + offset);
    cloud.intensities.push_back(static_cast<float>(i % 100));
  }
  return cloud;
}

std::vector<std::tuple<float, float, float, float>> allPoints(const LodTree& tree) {
  std::vector<std::tuple<float, float, float, float>> out;
  for (const LodNode& node : tree.nodes()) {
    const std::span<const float> xyzi = tree.points(node);
    for (std::size_t i = 0; i < node.count; ++i)
      out.emplace_back(xyzi[4 * i], xyzi[4 * i + 1], xyzi[4 * i + 2], xyzi[4 * i + 3]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(LodTree, EveryPointIsInExactlyOneNodeAndInsideItsCube) {
  const PointCloud cloud = forest(200000);
  const LodOptions options{.grid_cells = 32, .leaf_points = 2000};
  const LodTree tree = LodTree::build(cloud, options);
  ASSERT_GT(tree.nodes().size(), 20u);
  EXPECT_EQ(tree.pointCount(), cloud.size());

  std::vector<std::tuple<float, float, float, float>> expected;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = (cloud.positions[i] - tree.origin()).cast<float>();
    expected.emplace_back(p.x(), p.y(), p.z(), cloud.intensities[i]);
  }
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(allPoints(tree), expected);

  for (const LodNode& node : tree.nodes()) {
    const std::span<const float> xyzi = tree.points(node);
    for (std::size_t i = 0; i < node.count; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        EXPECT_GE(xyzi[4 * i + axis], node.min_m[axis]);
        EXPECT_LE(xyzi[4 * i + axis], node.max_m[axis]);
      }
    }
    const bool leaf =
        std::all_of(node.children.begin(), node.children.end(), [](int c) { return c < 0; });
    // An inner node keeps at most one point per cell of its grid.
    if (!leaf) {
      EXPECT_LE(node.count, 32u * 32u * 32u);
    }
    for (int c : node.children) {
      if (c < 0) continue;
      const LodNode& child = tree.nodes()[c];
      EXPECT_EQ(child.parent, &node - tree.nodes().data());
      EXPECT_EQ(child.depth, node.depth + 1);
      EXPECT_NEAR(child.max_m.x() - child.min_m.x(), 0.5f * (node.max_m.x() - node.min_m.x()),
                  1e-4);
      EXPECT_TRUE(((child.min_m - node.min_m).array() >= -1e-4f).all());
      EXPECT_TRUE(((node.max_m - child.max_m).array() >= -1e-4f).all());
    }
  }
}

// The root alone must show the whole map: its points spread over the ground and every stem,
// not a corner of it.
TEST(LodTree, TheRootIsAnEvenSubsampleOfTheWholeCloud) {
  const LodTree tree = LodTree::build(forest(200000), {.grid_cells = 64, .leaf_points = 2000});
  const LodNode& root = tree.nodes().front();
  const std::span<const float> xyzi = tree.points(root);
  ASSERT_GT(root.count, 2000u);
  ASSERT_LT(root.count, 100000u);
  int quadrants[2][2] = {{0, 0}, {0, 0}};
  double top_m = 0.0;
  for (std::size_t i = 0; i < root.count; ++i) {
    const Eigen::Vector3d p =
        tree.origin() + Eigen::Vector3d(xyzi[4 * i], xyzi[4 * i + 1], xyzi[4 * i + 2]);
    ++quadrants[p.x() > 30.0][p.y() > 20.0];
    top_m = std::max(top_m, p.z());
  }
  for (const auto& row : quadrants)
    for (int count : row) EXPECT_GT(count, static_cast<int>(root.count) / 8);
  EXPECT_GT(top_m, 19.0);  // the stems' tops are there
}

TEST(LodTree, ProjectedCoordinatesKeepMillimetresAndNonFinitePointsAreSkipped) {
  PointCloud cloud = forest(5000, Eigen::Vector3d(385000.0, 6672000.0, 40.0));  // EPSG:3067
  cloud.positions.push_back(Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  cloud.intensities.push_back(1.0f);
  const LodTree tree = LodTree::build(cloud);
  EXPECT_EQ(tree.pointCount(), 5000u);
  const LodNode& root = tree.nodes().front();
  const std::span<const float> xyzi = tree.points(root);
  ASSERT_EQ(root.count, 5000u);  // fewer than leaf_points: one node keeps them all
  for (std::size_t i = 0; i < root.count; ++i) {
    const Eigen::Vector3d back =
        tree.origin() + Eigen::Vector3d(xyzi[4 * i], xyzi[4 * i + 1], xyzi[4 * i + 2]);
    EXPECT_LT((back - cloud.positions[i]).norm(), 1e-3);
  }
}

TEST(LodTree, AnEmptyCloudHasNoNodesAndRepeatedPointsEndInALeaf) {
  EXPECT_TRUE(LodTree::build(PointCloud{}).nodes().empty());
  PointCloud same;
  same.positions.assign(50000, Eigen::Vector3d(1.0, 2.0, 3.0));
  const LodTree tree = LodTree::build(same, {.leaf_points = 100, .max_depth = 6});
  EXPECT_EQ(tree.pointCount(), 50000u);
  EXPECT_EQ(allPoints(tree).size(), 50000u);
  for (const LodNode& node : tree.nodes()) EXPECT_LE(node.depth, 6);
}

}  // namespace
}  // namespace taiga::view
