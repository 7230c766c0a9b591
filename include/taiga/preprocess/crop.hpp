#pragma once
// Removing points that are not the forest: returns from the rig itself (the operator, the
// harvester's cabin and boom: fixed boxes in the body frame, as in the thesis) and returns too
// close to or too far from the sensor to trust.

#include <Eigen/Core>
#include <span>

#include "taiga/core/box.hpp"
#include "taiga/core/point_cloud.hpp"

namespace taiga::preprocess {

using taiga::Box;
using taiga::OrientedBox;

/// The points outside every box (boxes in the cloud's frame), all channels kept, in their order.
PointCloud removeInsideBoxes(const PointCloud& cloud, std::span<const Box> boxes);
PointCloud removeInsideBoxes(const PointCloud& cloud, std::span<const OrientedBox> boxes);

/// The points whose distance from the frame's origin lies in [min_range_m, max_range_m].
PointCloud keepRange(const PointCloud& cloud, double min_range_m, double max_range_m);
/// Both in one pass (one copy of the kept points): in [min_range_m, max_range_m] and outside
/// every box.
PointCloud keepRangeOutsideBoxes(const PointCloud& cloud, double min_range_m, double max_range_m,
                                 std::span<const OrientedBox> boxes);

}  // namespace taiga::preprocess
