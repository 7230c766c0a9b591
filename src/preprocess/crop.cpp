#include "taiga/preprocess/crop.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace taiga::preprocess {

namespace {

// The kept points: the cloud's channels copied whole, then compacted in place. An index gather
// into fresh vectors cost 1.6x as much on harvester scans (preprocess_bench): each of its writes
// touched a new page.
template <class Keep>
PointCloud keepIf(const PointCloud& cloud, Keep keep) {
  std::vector<std::uint8_t> kept(cloud.size());
  std::size_t n_kept = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    n_kept += kept[i] = keep(cloud.positions[i]) ? 1 : 0;
  PointCloud out = cloud;
  if (n_kept < cloud.size()) out.keepWhere(kept);
  return out;
}

template <class AnyBox>
bool insideAny(std::span<const AnyBox> boxes, const Eigen::Vector3d& p) {
  return std::any_of(boxes.begin(), boxes.end(),
                     [&](const AnyBox& box) { return box.contains(p); });
}

template <class AnyBox>
PointCloud removeInside(const PointCloud& cloud, std::span<const AnyBox> boxes) {
  if (boxes.empty()) return cloud;
  return keepIf(cloud, [&](const Eigen::Vector3d& p) { return !insideAny(boxes, p); });
}

struct InRange {
  double min2, max2;
  InRange(double min_range_m, double max_range_m)
      : min2(min_range_m * min_range_m), max2(max_range_m * max_range_m) {}
  bool operator()(const Eigen::Vector3d& p) const {
    const double r2 = p.squaredNorm();
    return r2 >= min2 && r2 <= max2;
  }
};

}  // namespace

PointCloud removeInsideBoxes(const PointCloud& cloud, std::span<const Box> boxes) {
  return removeInside(cloud, boxes);
}

PointCloud removeInsideBoxes(const PointCloud& cloud, std::span<const OrientedBox> boxes) {
  return removeInside(cloud, boxes);
}

PointCloud keepRange(const PointCloud& cloud, double min_range_m, double max_range_m) {
  return keepIf(cloud, InRange(min_range_m, max_range_m));
}

PointCloud keepRangeOutsideBoxes(const PointCloud& cloud, double min_range_m, double max_range_m,
                                 std::span<const OrientedBox> boxes) {
  const InRange in_range(min_range_m, max_range_m);
  return keepIf(cloud,
                [&](const Eigen::Vector3d& p) { return in_range(p) && !insideAny(boxes, p); });
}

}  // namespace taiga::preprocess
