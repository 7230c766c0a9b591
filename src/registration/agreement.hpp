#pragma once
// agreement() over any nearest-point index with nearestWithin(query, max, index, d2, hint) and
// kNoHint (KdTree, VoxelNearest): the same sums in the same order, so the same figures.

#include <limits>
#include <span>

#include "block_reduce.hpp"
#include "taiga/lie/se3.hpp"
#include "taiga/registration/kdtree.hpp"

namespace taiga::registration::detail {

template <class Index>
Agreement agreementWith(std::span<const Eigen::Vector3d> source, const Index& target,
                        const lie::SE3& T_target_source, double max_distance_m) {
  struct Partial {
    double sum = 0.0;
    std::size_t count = 0;
    std::size_t previous = Index::kNoHint;  ///< the block's previous query's nearest point
  };
  const Eigen::Matrix3d R = T_target_source.rotation().matrix();
  const Eigen::Vector3d t = T_target_source.translation();
  const Partial total = reduceInBlocks<Partial>(
      source.size(),
      [&](std::size_t i, Partial& out) {
        // The source comes in voxel order: the previous point's nearest is a near hint.
        std::size_t index;
        double sq;
        if (target.nearestWithin(R * source[i] + t, max_distance_m, index, sq, out.previous)) {
          out.sum += sq;
          ++out.count;
          out.previous = index;
        }
      },
      [](Partial& a, const Partial& b) {
        a.sum += b.sum;
        a.count += b.count;
      });
  Agreement a;
  a.fitness_m2 = total.count == 0 ? std::numeric_limits<double>::quiet_NaN()
                                  : total.sum / static_cast<double>(total.count);
  a.share =
      source.empty() ? 0.0 : static_cast<double>(total.count) / static_cast<double>(source.size());
  return a;
}

}  // namespace taiga::registration::detail
