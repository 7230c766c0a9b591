#include "taiga/view/lod_tree.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace taiga::view {
namespace {

struct Builder {
  std::vector<float>& xyzi;
  const LodOptions& options;
  std::vector<LodNode>& nodes;
  /// Per point position: 0 to stay in the node being filled, 1 + octant to go to a child.
  std::vector<std::uint8_t>& buckets;

  Eigen::Vector3f point(std::size_t k) const {
    return {xyzi[4 * k], xyzi[4 * k + 1], xyzi[4 * k + 2]};
  }

  /// Node `index` over the points [first, last): its subsample moved to the front, then its
  /// children's points, octant by octant.
  void fill(int index, std::size_t first, std::size_t last) {
    nodes[index].first = first;
    const bool leaf =
        last - first <= options.leaf_points || nodes[index].depth >= options.max_depth;
    if (leaf) {
      nodes[index].count = last - first;
      return;
    }
    const Eigen::Vector3f min_m = nodes[index].min_m;
    const float edge_m = nodes[index].max_m.x() - min_m.x();
    const float cell_m = edge_m / static_cast<float>(options.grid_cells);
    const float half_m = 0.5f * edge_m;
    // The first point in each grid cell stays in this node; the others go to the octants.
    const std::size_t g = static_cast<std::size_t>(options.grid_cells);
    std::vector<bool> taken(g * g * g);  // 32 KB at 64 cells: cheaper than hashing
    std::array<std::size_t, 9> per_bucket{};
    for (std::size_t k = first; k < last; ++k) {
      const Eigen::Vector3f local = point(k) - min_m;
      const auto cell = [&](int axis) {
        return static_cast<std::size_t>(
            std::clamp(static_cast<int>(local[axis] / cell_m), 0, options.grid_cells - 1));
      };
      const std::size_t key = (cell(2) * g + cell(1)) * g + cell(0);
      std::uint8_t bucket = 0;
      if (taken[key]) {
        bucket = 1 + ((local.x() >= half_m ? 1 : 0) | (local.y() >= half_m ? 2 : 0) |
                      (local.z() >= half_m ? 4 : 0));
      } else {
        taken[key] = true;
      }
      buckets[k] = bucket;
      ++per_bucket[bucket];
    }
    const std::array<std::size_t, 10> begin = sortIntoBuckets(first, per_bucket);
    nodes[index].count = per_bucket[0];

    const int depth = nodes[index].depth;
    for (int o = 0; o < 8; ++o) {
      if (per_bucket[o + 1] == 0) continue;
      LodNode child;
      child.depth = depth + 1;
      child.parent = index;
      child.min_m = min_m + Eigen::Vector3f((o & 1) ? half_m : 0.f, (o & 2) ? half_m : 0.f,
                                            (o & 4) ? half_m : 0.f);
      child.max_m = child.min_m + Eigen::Vector3f::Constant(half_m);
      const int child_index = static_cast<int>(nodes.size());
      nodes[index].children[o] = child_index;
      nodes.push_back(child);  // invalidates references into nodes
      fill(child_index, begin[o + 1], begin[o + 2]);
    }
  }

  /// Moves the points from `first` on into their buckets, in place (an American flag sort: each
  /// point is swapped straight to its bucket's next free place); returns where each bucket begins.
  std::array<std::size_t, 10> sortIntoBuckets(std::size_t first,
                                              const std::array<std::size_t, 9>& per_bucket) {
    std::array<std::size_t, 10> begin{};
    begin[0] = first;
    for (int b = 0; b < 9; ++b) begin[b + 1] = begin[b] + per_bucket[b];
    std::array<std::size_t, 9> next;
    std::copy_n(begin.begin(), 9, next.begin());
    for (int b = 0; b < 9; ++b) {
      while (next[b] < begin[b + 1]) {
        const std::size_t k = next[b];
        const std::uint8_t belongs = buckets[k];
        if (belongs == b) {
          ++next[b];
          continue;
        }
        const std::size_t to = next[belongs]++;
        std::swap_ranges(&xyzi[4 * k], &xyzi[4 * k + 4], &xyzi[4 * to]);
        std::swap(buckets[k], buckets[to]);
      }
    }
    return begin;
  }
};

}  // namespace

void LodPoints::append(const PointCloud& cloud) {
  xyzi.reserve(xyzi.size() + 4 * cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.positions[i];
    if (!p.allFinite()) continue;
    if (xyzi.empty()) origin = (p / 100.0).array().floor() * 100.0;
    const Eigen::Vector3f local = (p - origin).cast<float>();
    xyzi.insert(xyzi.end(), {local.x(), local.y(), local.z(),
                             cloud.hasIntensities() ? cloud.intensities[i] : 0.0f});
  }
}

LodTree LodTree::build(const PointCloud& cloud, const LodOptions& options) {
  LodPoints points;
  points.append(cloud);
  return build(std::move(points), options);
}

LodTree LodTree::build(LodPoints points, const LodOptions& options) {
  LodTree tree;
  tree.points_ = std::move(points);
  const std::size_t n = tree.points_.size();
  if (n == 0) return tree;
  const std::vector<float>& xyzi = tree.points_.xyzi;
  Eigen::AlignedBox3f box;
  for (std::size_t i = 0; i < n; ++i)
    box.extend(Eigen::Vector3f(xyzi[4 * i], xyzi[4 * i + 1], xyzi[4 * i + 2]));

  // A cube around the box, a little larger so that no point lies on its far faces.
  const float edge_m = std::max(box.sizes().maxCoeff(), 1e-3f) * 1.001f;
  LodNode root;
  root.min_m = box.min();
  root.max_m = root.min_m + Eigen::Vector3f::Constant(edge_m);
  tree.nodes_.push_back(root);
  std::vector<std::uint8_t> buckets(n);
  Builder{tree.points_.xyzi, options, tree.nodes_, buckets}.fill(0, 0, n);
  return tree;
}

}  // namespace taiga::view
