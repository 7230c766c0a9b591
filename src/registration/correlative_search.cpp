#include "taiga/registration/correlative_search.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "taiga/core/angles.hpp"

namespace taiga::registration {
namespace {

std::vector<VoxelKey> occupiedKeys(std::span<const Eigen::Vector3d> target, double inverse_m) {
  std::vector<VoxelKey> keys;
  keys.reserve(target.size());
  for (const Eigen::Vector3d& p : target) {
    const VoxelKey key = voxelOf(p, inverse_m);
    if (key != kInvalidVoxel) keys.push_back(key);
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

/// An even subsample of at most `n` points.
std::vector<Eigen::Vector3d> subsample(std::span<const Eigen::Vector3d> points, std::size_t n) {
  if (points.size() <= n) return {points.begin(), points.end()};
  std::vector<Eigen::Vector3d> out;
  out.reserve(n);
  for (std::size_t k = 0; k < n; ++k) out.push_back(points[k * points.size() / n]);
  return out;
}

int stepsEachSide(double half, double step) {
  return step > 0.0 ? static_cast<int>(std::floor(half / step + 1e-9)) : 0;
}

}  // namespace

Occupancy::Occupancy(std::span<const Eigen::Vector3d> target, double voxel_m)
    : inverse_m_(1.0 / voxel_m), index_(occupiedKeys(target, 1.0 / voxel_m)) {}

std::vector<CorrelativeCandidate> correlativeSearch(std::span<const Eigen::Vector3d> source,
                                                    const Occupancy& target,
                                                    const lie::SE3& guess_T_target_source,
                                                    const CorrelativeWindow& window,
                                                    std::size_t max_candidates) {
  const std::vector<Eigen::Vector3d> scored = subsample(source, window.max_source);
  if (scored.empty() || max_candidates == 0) return {};
  const int n_yaw = stepsEachSide(window.yaw_half_deg, window.yaw_step_deg);
  const int n_xy = stepsEachSide(window.xy_half_m, window.xy_step_m);
  const int yaws = 2 * n_yaw + 1, side = 2 * n_xy + 1;
  // hits[(yaw * side + ix) * side + iy]: scored points in occupied voxels at that pose.
  std::vector<int> hits(static_cast<std::size_t>(yaws) * side * side, 0);
  const Eigen::Matrix3d R_guess = guess_T_target_source.rotation().matrix();
  const Eigen::Vector3d t_guess = guess_T_target_source.translation();
  tbb::parallel_for(0, yaws, [&](int k) {
    const double yaw_rad = (k - n_yaw) * window.yaw_step_deg * kRadPerDeg;
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_guess;
    int* pose_hits = hits.data() + static_cast<std::size_t>(k) * side * side;
    for (const Eigen::Vector3d& p : scored) {
      const Eigen::Vector3d q = R * p + t_guess;
      for (int ix = 0; ix < side; ++ix) {
        const double dx = (ix - n_xy) * window.xy_step_m;
        for (int iy = 0; iy < side; ++iy) {
          const double dy = (iy - n_xy) * window.xy_step_m;
          pose_hits[ix * side + iy] += target.occupied(q + Eigen::Vector3d(dx, dy, 0.0));
        }
      }
    }
  });

  // Best first; equal scores in grid order, so the answer does not depend on the threads.
  std::vector<std::size_t> order(hits.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return hits[a] > hits[b]; });
  struct GridPose {
    int yaw, ix, iy;
  };
  const auto gridPose = [&](std::size_t i) {
    return GridPose{static_cast<int>(i / (side * side)), static_cast<int>(i / side % side),
                    static_cast<int>(i % side)};
  };
  std::vector<GridPose> kept;
  std::vector<CorrelativeCandidate> out;
  for (const std::size_t i : order) {
    if (out.size() >= max_candidates) break;
    const GridPose g = gridPose(i);
    const bool near_better = std::any_of(kept.begin(), kept.end(), [&](const GridPose& k) {
      return std::abs(k.yaw - g.yaw) <= 2 && std::abs(k.ix - g.ix) <= 2 &&
             std::abs(k.iy - g.iy) <= 2;
    });
    if (near_better) continue;
    kept.push_back(g);
    const double yaw_rad = (g.yaw - n_yaw) * window.yaw_step_deg * kRadPerDeg;
    const lie::SO3 turn = lie::SO3::fromRollPitchYaw(0.0, 0.0, yaw_rad);
    const Eigen::Vector3d shift((g.ix - n_xy) * window.xy_step_m, (g.iy - n_xy) * window.xy_step_m,
                                0.0);
    out.push_back({lie::SE3(turn * guess_T_target_source.rotation(), t_guess + shift),
                   static_cast<double>(hits[i]) / static_cast<double>(scored.size())});
  }
  return out;
}

}  // namespace taiga::registration
