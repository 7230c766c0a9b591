#pragma once
// Levels of detail for a large point cloud in a browser (docs/viewer.md): an octree whose every
// node keeps an even subsample of the points in its cube (one point per cell of a
// grid_cells^3 grid over the cube) and hands the rest to its children. A page that shows the root
// sees the whole map coarsely; refining a node in view adds its children's points to its own, so
// what is drawn near the camera gets denser while the far map stays coarse (the nested scheme of
// Potree, Schuetz 2016). Every input point is in exactly one node.
//
// The points are held once, moved in place so that each node's points are contiguous: 16 bytes
// per point (a 100 million point map in 1.6 GB), 17 while the tree is built.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "taiga/core/point_cloud.hpp"

namespace taiga::view {

struct LodOptions {
  int grid_cells = 64;              ///< a node keeps at most one point per (edge/grid_cells)^3 cell
  std::size_t leaf_points = 20000;  ///< a node with this many points or fewer keeps them all
  int max_depth = 16;               ///< a node this deep keeps all its points
};

struct LodNode {
  Eigen::Vector3f min_m, max_m;  ///< the node's cube, relative to LodTree::origin()
  int depth = 0;
  int parent = -1;
  std::array<int, 8> children{-1, -1, -1, -1, -1, -1, -1, -1};  ///< -1: none
  std::size_t first = 0, count = 0;  ///< its points: LodTree::points(node)
};

/// Points relative to an origin, as the page receives them: x, y, z (m) and intensity per point,
/// interleaved float32.
struct LodPoints {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<float> xyzi;
  /// Appends the finite points of `cloud` (intensity 0 where it has none). The first finite
  /// point fixes the origin (rounded to 100 m), so float32 keeps millimetres on projected
  /// coordinates.
  void append(const PointCloud& cloud);
  std::size_t size() const { return xyzi.size() / 4; }
};

class LodTree {
 public:
  /// The tree of `points` (taken: they are reordered node by node).
  static LodTree build(LodPoints points, const LodOptions& options = {});
  static LodTree build(const PointCloud& cloud, const LodOptions& options = {});

  const Eigen::Vector3d& origin() const { return points_.origin; }
  /// Node 0 is the root (absent when there was no finite point).
  const std::vector<LodNode>& nodes() const { return nodes_; }
  std::size_t pointCount() const { return points_.size(); }
  /// A node's points, 4 floats each (LodPoints::xyzi).
  std::span<const float> points(const LodNode& node) const {
    return std::span<const float>(points_.xyzi).subspan(4 * node.first, 4 * node.count);
  }

 private:
  LodPoints points_;
  std::vector<LodNode> nodes_;
};

}  // namespace taiga::view
