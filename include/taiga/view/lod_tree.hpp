#pragma once
// Levels of detail for a large point cloud in a browser (docs/viewer.md): an octree whose every
// node keeps an even subsample of the points in its cube (one point per cell of a
// grid_cells^3 grid over the cube) and hands the rest to its children. A page that shows the root
// sees the whole map coarsely; refining a node in view adds its children's points to its own, so
// what is drawn near the camera gets denser while the far map stays coarse (the nested scheme of
// Potree, Schuetz 2016). Every input point is in exactly one node.

#include <Eigen/Core>
#include <array>
#include <cstdint>
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
  /// x, y, z (relative to the origin, m) and intensity per point, interleaved as float32: the
  /// bytes the page receives.
  std::vector<float> xyzi;
  std::size_t points() const { return xyzi.size() / 4; }
};

class LodTree {
 public:
  /// The tree of `cloud`'s finite points; intensities are 0 where the cloud has none. The origin
  /// is a round point near the cloud, so float32 keeps millimetres on projected coordinates.
  static LodTree build(const PointCloud& cloud, const LodOptions& options = {});

  const Eigen::Vector3d& origin() const { return origin_; }
  /// Node 0 is the root (absent when the cloud had no finite point).
  const std::vector<LodNode>& nodes() const { return nodes_; }
  std::size_t pointCount() const { return point_count_; }

 private:
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  std::vector<LodNode> nodes_;
  std::size_t point_count_ = 0;
};

}  // namespace taiga::view
