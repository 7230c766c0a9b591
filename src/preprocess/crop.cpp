#include "taiga/preprocess/crop.hpp"

#include <algorithm>
#include <vector>

namespace taiga::preprocess {

PointCloud removeInsideBoxes(const PointCloud& cloud, std::span<const Box> boxes) {
  std::vector<std::size_t> kept;
  kept.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.positions[i];
    if (std::none_of(boxes.begin(), boxes.end(), [&](const Box& box) { return box.contains(p); }))
      kept.push_back(i);
  }
  return cloud.select(kept);
}

PointCloud keepRange(const PointCloud& cloud, double min_range_m, double max_range_m) {
  std::vector<std::size_t> kept;
  kept.reserve(cloud.size());
  const double min2 = min_range_m * min_range_m, max2 = max_range_m * max_range_m;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double r2 = cloud.positions[i].squaredNorm();
    if (r2 >= min2 && r2 <= max2) kept.push_back(i);
  }
  return cloud.select(kept);
}

}  // namespace taiga::preprocess
