#include "taiga/preprocess/crop.hpp"

#include <algorithm>
#include <vector>

namespace taiga::preprocess {

namespace {

template <class AnyBox>
PointCloud removeInside(const PointCloud& cloud, std::span<const AnyBox> boxes) {
  if (boxes.empty()) return cloud;
  std::vector<std::size_t> kept;
  kept.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.positions[i];
    if (std::none_of(boxes.begin(), boxes.end(), [&](const AnyBox& box) { return box.contains(p); }))
      kept.push_back(i);
  }
  return cloud.select(kept);
}

}  // namespace

PointCloud removeInsideBoxes(const PointCloud& cloud, std::span<const Box> boxes) {
  return removeInside(cloud, boxes);
}

PointCloud removeInsideBoxes(const PointCloud& cloud, std::span<const OrientedBox> boxes) {
  return removeInside(cloud, boxes);
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
