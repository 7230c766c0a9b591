// The local map's work per keyframe, stage by stage, on one thread (issue 26, "profile first"):
// a run's keyframes are replayed into the structures LocalMap keeps (pipeline/local_map.hpp),
// each added at its pose and the oldest dropped beyond the map's size, as `taiga run` does.
// Stages: the point statistics' update (one mean per local_map_voxel_m voxel), the NDT cells'
// statistics' update (with the range noise's shares), the NDT target's build, the means and the
// nearest-point index over them (and, for comparison, the kd-tree it replaced and the fitness's
// queries in both, which must agree bit for bit). Each stage's median over the keyframes is
// printed, then the median over RUNS passes. In `taiga run` this runs beside the scans'
// registration, on the same two cores: the scan after next waits for it (bench/BENCHMARK.md,
// "Session 65").
//
// The last line is a checksum of what the structures hold (every NDT cell and indexed point, bit
// for bit, in any order): an optimization that should not change them must not change it.
//
//   local_map_bench RUN CONFIG [RUNS=3]   RUN: a `taiga run` output directory (keyframes.tum and
//                                         keyframes/); CONFIG: the run's --config
#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/mapping/keyframe_file.hpp"
#include "taiga/pipeline/local_map.hpp"
#include "taiga/preprocess/voxel_filter.hpp"
#include "taiga/registration/kdtree.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/voxel_nearest.hpp"
#include "taiga/registration/voxel_statistics.hpp"

using namespace taiga;
using bench::Clock;
using bench::median;
using bench::msSince;

namespace {

/// FNV-1a of an object's bytes.
template <class T>
std::uint64_t hashOf(const T& value) {
  return bench::fnv1a(&value, sizeof(T));
}

/// A sum of the elements' hashes: the same for the same elements in any order.
std::uint64_t checksum(const registration::NdtTarget& target,
                       const std::vector<Eigen::Vector3d>& points) {
  std::uint64_t sum = 0;
  for (const registration::NdtCell& cell : target.cells()) {
    sum += hashOf(cell.mean) ^ hashOf(cell.inverse_covariance) ^ hashOf(cell.stem_centre) ^
           hashOf(cell.stem_radius_m) ^ hashOf(cell.inverse_radial_variance);
  }
  for (const Eigen::Vector3d& p : points) sum += hashOf(p);
  return sum;
}

struct Keyframe {
  std::vector<Eigen::Vector3d> points_in_odom;
  registration::BeamNoise beams;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    fmt::print(stderr, "usage: local_map_bench RUN CONFIG [RUNS=3]\n");
    return 2;
  }
  const std::string run_dir = argv[1];
  const int runs = argc > 3 ? std::atoi(argv[3]) : 3;
  SystemConfig config;
  io::readConfigYaml(argv[2], config);
  const OdometryConfig& o = config.odometry;
  const Trajectory keyframe_poses = io::readTum(run_dir + "/keyframes.tum");
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);

  // The local map's points of each keyframe, as Odometry gives them (ScanPreparation::
  // localMapPoints), at the keyframe's pose in keyframes.tum.
  const Eigen::Vector3d p_body_lidar = config.rig.T_body_lidar.translation();
  std::vector<Keyframe> keyframes;
  for (std::size_t k = 0; k < keyframe_poses.size(); ++k) {
    const auto content =
        mapping::readKeyframeFile(fmt::format("{}/keyframes/{:06d}.tkf", run_dir, k));
    const lie::SE3& T_odom_keyframe = keyframe_poses[k].pose;
    Keyframe keyframe;
    keyframe.points_in_odom =
        preprocess::voxelFilter(content.cloud_in_body, o.local_map_voxel_m,
                                preprocess::voxelRepresentative(o.local_map_point), p_body_lidar)
            .positions;
    for (Eigen::Vector3d& p : keyframe.points_in_odom) p = T_odom_keyframe * p;
    keyframe.beams = {T_odom_keyframe * p_body_lidar,
                      o.ndt_stem_cells_range_noise ? o.lidar_range_sigma_m : 0.0,
                      o.ndt_stem_cells_range_noise ? o.lidar_range_sigma_per_m : 0.0};
    keyframes.push_back(std::move(keyframe));
  }
  registration::NdtConfig rules;
  rules.resolution_m = o.ndt_resolution_m;
  rules.stem_cells = o.ndt_stem_cells;
  rules.stem_cells_across_borders = o.ndt_stem_cells_across_borders;

  // The stages LocalMap runs, then for comparison the kd-tree it used before (over the means
  // sorted by key) and the fitness's queries in either: 4000 of the next keyframe's points, as a
  // scan's would come, within 2 m (two coarse NDT cells).
  const char* names[] = {"point statistics",
                         "NDT statistics",
                         "NDT target",
                         "means",
                         "nearest index",
                         "sum",
                         "sorted means + kd-tree (before)",
                         "queries, kd-tree",
                         "queries, index"};
  constexpr int kStages = 6, kExtras = 3;
  std::vector<std::vector<double>> per_run(kStages + kExtras);
  std::size_t mismatches = 0;
  std::uint64_t hash = 0;
  std::size_t cells = 0, points = 0;
  for (int run = 0; run < runs; ++run) {
    registration::VoxelMeans point_statistics(o.local_map_voxel_m);
    registration::VoxelStatistics ndt_statistics(o.ndt_resolution_m, rules.stem_cells);
    std::deque<const Keyframe*> window;
    std::vector<std::vector<double>> ms(kStages + kExtras);
    hash = 0;
    for (std::size_t k = 0; k < keyframes.size(); ++k) {
      const Keyframe& keyframe = keyframes[k];
      window.push_back(&keyframe);
      const Keyframe* dropped = nullptr;
      if (static_cast<int>(window.size()) > o.local_map_keyframes) {
        dropped = window.front();
        window.pop_front();
      }
      double stage_ms[kStages] = {};
      auto start = Clock::now();
      point_statistics.add(keyframe.points_in_odom);
      if (dropped) point_statistics.remove(dropped->points_in_odom);
      stage_ms[0] = msSince(start);
      start = Clock::now();
      ndt_statistics.add(keyframe.points_in_odom, keyframe.beams);
      if (dropped) ndt_statistics.remove(dropped->points_in_odom, dropped->beams);
      stage_ms[1] = msSince(start);
      start = Clock::now();
      const registration::NdtTarget target(ndt_statistics, rules);
      stage_ms[2] = msSince(start);
      start = Clock::now();
      const std::vector<Eigen::Vector3d> means = point_statistics.meansInTableOrder();
      stage_ms[3] = msSince(start);
      start = Clock::now();
      const registration::VoxelNearest index(means, pipeline::LocalMap::kNearestCell_m);
      stage_ms[4] = msSince(start);
      for (int s = 0; s < kStages - 1; ++s) stage_ms[kStages - 1] += stage_ms[s];
      for (int s = 0; s < kStages; ++s) ms[s].push_back(stage_ms[s]);

      start = Clock::now();
      const registration::KdTree tree(point_statistics.means());
      ms[kStages].push_back(msSince(start));
      if (k + 1 < keyframes.size()) {
        const auto& next = keyframes[k + 1].points_in_odom;
        std::vector<Eigen::Vector3d> sample;
        for (std::size_t i = 0; i < next.size(); i += std::max<std::size_t>(1, next.size() / 4000))
          sample.push_back(next[i]);
        start = Clock::now();
        const registration::Agreement by_tree = registration::agreement(sample, tree, {}, 2.0);
        ms[kStages + 1].push_back(msSince(start));
        start = Clock::now();
        const registration::Agreement by_index = registration::agreement(sample, index, {}, 2.0);
        ms[kStages + 2].push_back(msSince(start));
        if (!(by_tree.fitness_m2 == by_index.fitness_m2 && by_tree.share == by_index.share))
          ++mismatches;
      }
      hash += checksum(target, index.points());
      cells = target.cells().size();
      points = index.size();
    }
    for (int s = 0; s < kStages + kExtras; ++s) per_run[s].push_back(median(ms[s]));
  }
  fmt::print("{} keyframes, {} in the map; at the end {} NDT cells of {} m, {} points of {} m\n",
             keyframes.size(), o.local_map_keyframes, cells, o.ndt_resolution_m, points,
             o.local_map_voxel_m);
  fmt::print("median ms per keyframe (one thread; median of {} runs):\n", runs);
  for (int s = 0; s < kStages + kExtras; ++s)
    fmt::print("  {:32s} {:7.2f}\n", names[s], median(per_run[s]));
  fmt::print("the fitness by the index and by the kd-tree differed on {} keyframes\n", mismatches);
  fmt::print("checksum {:016x}\n", hash);
}
