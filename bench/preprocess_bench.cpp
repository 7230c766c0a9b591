// The odometry's per-scan preprocessing, stage by stage, on a recording's scans (issue 26,
// "profile first"): crop (range and boxes), deskew, the registration's voxel filter and the
// keyframe's. Each stage is timed per scan, the median over the scans is printed, and the
// median over RUNS passes of the whole set. The deskew uses the ground truth trajectory (it
// costs the same with any trajectory). The last line is a checksum of every stage's output (the
// deskewed points and both voxel filters' points, bit for bit): an optimization that should not
// change them must not change it.
//
//   preprocess_bench SIM [RUNS=3] [SCANS=100]     SIM: a `taiga simulate` output directory
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/preprocess/crop.hpp"
#include "taiga/preprocess/deskew.hpp"
#include "taiga/preprocess/voxel_filter.hpp"

using namespace taiga;
using bench::Clock;
using bench::median;
using bench::msSince;

int main(int argc, char** argv) {
  if (argc < 2) {
    fmt::print(stderr, "usage: preprocess_bench SIM [RUNS=3] [SCANS=100]\n");
    return 2;
  }
  const std::string sim = argv[1];
  const int runs = argc > 2 ? std::atoi(argv[2]) : 3;
  const std::size_t max_scans = argc > 3 ? std::strtoul(argv[3], nullptr, 10) : 100;
  SystemConfig config;
  io::readConfigYaml(sim + "/rig.yaml", config);
  const Trajectory truth = io::readTum(sim + "/groundtruth.tum");
  io::Recording recording = io::openRecording(sim + "/recording.bag", config.recording, config.rig);
  std::vector<io::Scan> scans;
  while (auto event = recording.next()) {
    auto* scan = std::get_if<io::Scan>(&*event);
    if (scan == nullptr || !truth.covers(scan->t_start_s) || !truth.covers(scan->t_end_s)) continue;
    scans.push_back(std::move(*scan));
    if (scans.size() == max_scans) break;
  }
  const OdometryConfig& o = config.odometry;
  const auto representative = preprocess::voxelRepresentative(o.voxel_point);
  const std::vector<OrientedBox> no_boxes;

  const char* names[] = {"crop", "deskew", "voxel (scan)", "voxel (keyframe)", "sum"};
  std::vector<std::vector<double>> per_run(5);
  std::size_t points = 0, kept = 0, voxels = 0;
  std::uint64_t hash = bench::kFnvOffset;
  for (int run = 0; run < runs; ++run) {
    std::vector<std::vector<double>> ms(5);
    for (const io::Scan& scan : scans) {
      auto start = Clock::now();
      PointCloud cropped = preprocess::keepRangeOutsideBoxes(scan.cloud_in_lidar, o.min_range_m,
                                                             o.max_range_m, no_boxes);
      ms[0].push_back(msSince(start));
      start = Clock::now();
      const std::size_t n = cropped.size();
      PointCloud in_body =
          preprocess::deskew(std::move(cropped), config.rig.T_body_lidar, truth, scan.t_end_s)
              .cloud_in_body;
      ms[1].push_back(msSince(start));
      start = Clock::now();
      const PointCloud source = preprocess::voxelFilter(in_body, o.voxel_size_m, representative);
      ms[2].push_back(msSince(start));
      start = Clock::now();
      const PointCloud keyframe = preprocess::voxelFilter(in_body, o.local_map_voxel_m);
      ms[3].push_back(msSince(start));
      ms[4].push_back(ms[0].back() + ms[1].back() + ms[2].back());
      points += scan.cloud_in_lidar.size();
      kept += n;
      voxels += source.size();
      if (run == 0)
        hash = bench::fnv1a(keyframe.positions,
                            bench::fnv1a(source.positions, bench::fnv1a(in_body.positions, hash)));
    }
    for (int s = 0; s < 5; ++s) per_run[s].push_back(median(ms[s]));
  }
  const double per_scan = static_cast<double>(runs) * static_cast<double>(scans.size());
  fmt::print("{} scans x {} runs; per scan {:.0f} points, {:.0f} after the crop, {:.0f} voxels\n",
             scans.size(), runs, points / per_scan, kept / per_scan, voxels / per_scan);
  fmt::print(
      "median ms per scan (median over runs); sum: what every scan pays (not the "
      "keyframe's voxel filter)\n");
  for (int s = 0; s < 5; ++s) fmt::print("  {:18s} {:7.3f}\n", names[s], median(per_run[s]));
  fmt::print("checksum of the outputs {:016x}\n", hash);
  return 0;
}
