#pragma once
// Removing points that are not the forest: returns from the rig itself (the operator, the
// harvester's cabin and boom: fixed boxes in the body frame, as in the thesis) and returns too
// close to or too far from the sensor to trust.

#include <Eigen/Core>
#include <span>

#include "taiga/core/point_cloud.hpp"

namespace taiga::preprocess {

/// An axis-aligned box in the frame of the cloud it is applied to.
struct Box {
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_m = Eigen::Vector3d::Zero();
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= min_m.array()).all() && (p.array() <= max_m.array()).all();
  }
};

/// The points outside every box, all channels kept, in their order.
PointCloud removeInsideBoxes(const PointCloud& cloud, std::span<const Box> boxes);

/// The points whose distance from the frame's origin lies in [min_range_m, max_range_m].
PointCloud keepRange(const PointCloud& cloud, double min_range_m, double max_range_m);

}  // namespace taiga::preprocess
