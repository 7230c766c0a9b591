#include "taiga/view/lod_tree.hpp"

#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>

namespace taiga::view {
namespace {

struct Builder {
  const std::vector<Eigen::Vector3f>& points;
  const std::vector<float>& intensities;
  const LodOptions& options;
  std::vector<LodNode>& nodes;

  void keep(LodNode& node, std::uint32_t i) const {
    const Eigen::Vector3f& p = points[i];
    node.xyzi.insert(node.xyzi.end(), {p.x(), p.y(), p.z(), intensities[i]});
  }

  /// Node `index` over `members`: its subsample kept, the rest split among the children.
  void fill(int index, std::vector<std::uint32_t> members) {
    LodNode& node = nodes[index];
    const bool leaf = members.size() <= options.leaf_points || node.depth >= options.max_depth;
    if (leaf) {
      node.xyzi.reserve(members.size() * 4);
      for (std::uint32_t i : members) keep(node, i);
      return;
    }
    const Eigen::Vector3f min_m = node.min_m;
    const float edge_m = node.max_m.x() - node.min_m.x();
    const float cell_m = edge_m / static_cast<float>(options.grid_cells);
    const float half_m = 0.5f * edge_m;
    const int depth = node.depth;
    const std::size_t g = static_cast<std::size_t>(options.grid_cells);
    std::vector<bool> taken(g * g * g);  // 32 KB at 64 cells: cheaper than hashing
    std::array<std::vector<std::uint32_t>, 8> child_members;
    for (std::uint32_t i : members) {
      const Eigen::Vector3f local = points[i] - min_m;
      const auto cell = [&](int axis) {
        return static_cast<std::size_t>(
            std::clamp(static_cast<int>(local[axis] / cell_m), 0, options.grid_cells - 1));
      };
      const std::size_t key = (cell(2) * g + cell(1)) * g + cell(0);
      if (!taken[key]) {
        taken[key] = true;
        keep(nodes[index], i);
        continue;
      }
      const int octant = (local.x() >= half_m ? 1 : 0) | (local.y() >= half_m ? 2 : 0) |
                         (local.z() >= half_m ? 4 : 0);
      child_members[octant].push_back(i);
    }
    members = {};
    for (int octant = 0; octant < 8; ++octant) {
      if (child_members[octant].empty()) continue;
      LodNode child;
      child.depth = depth + 1;
      child.parent = index;
      const Eigen::Vector3f offset((octant & 1) ? half_m : 0.f, (octant & 2) ? half_m : 0.f,
                                   (octant & 4) ? half_m : 0.f);
      child.min_m = min_m + offset;
      child.max_m = child.min_m + Eigen::Vector3f::Constant(half_m);
      const int child_index = static_cast<int>(nodes.size());
      nodes[index].children[octant] = child_index;
      nodes.push_back(std::move(child));  // invalidates references into nodes
      fill(child_index, std::move(child_members[octant]));
    }
  }
};

}  // namespace

LodTree LodTree::build(const PointCloud& cloud, const LodOptions& options) {
  LodTree tree;
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : cloud.positions)
    if (p.allFinite()) box.extend(p);
  if (box.isEmpty()) return tree;
  tree.origin_ = (box.min() / 100.0).array().floor() * 100.0;

  std::vector<Eigen::Vector3f> points;
  std::vector<float> intensities;
  std::vector<std::uint32_t> members;
  points.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.positions[i].allFinite()) continue;
    members.push_back(static_cast<std::uint32_t>(points.size()));
    points.push_back((cloud.positions[i] - tree.origin_).cast<float>());
    intensities.push_back(cloud.hasIntensities() ? cloud.intensities[i] : 0.0f);
  }
  tree.point_count_ = points.size();

  // A cube around the box, a little larger so that no point lies on its far faces.
  const double edge_m = std::max(box.sizes().maxCoeff(), 1e-3) * 1.001;
  LodNode root;
  root.min_m = (box.min() - tree.origin_).cast<float>();
  root.max_m = root.min_m + Eigen::Vector3f::Constant(static_cast<float>(edge_m));
  tree.nodes_.push_back(root);
  Builder{points, intensities, options, tree.nodes_}.fill(0, std::move(members));
  return tree;
}

}  // namespace taiga::view
