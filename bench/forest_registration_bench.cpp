// Registration benchmark on a simulated forest, the case of issue 5: a 0.4 m-voxelized OS0-128
// scan (128 beams x 1024 columns; 'mixed' forest walk, seed 7, the first place of
// tests/registration/forest_registration_test.cpp) registered to a local map of 15 keyframes about
// 1 m apart (each deskewed with the ground truth, in the world frame, voxelized at 0.2 m as the
// odometry's local map is). Our NDT, D2D-NDT and GICP against PCL 1.13's
// NormalDistributionsTransform and GeneralizedIterativeClosestPoint on the same clouds, from the
// same guesses, in one process; ours at 1 and 2 TBB threads (tbb::global_control), PCL's are
// single-threaded. Errors are against the true T_world_body at the scan's end.
//
// Timed per scan, as in the odometry: the map side (NDT cells, GICP target covariances) is built
// once per keyframe, not per scan, so it is timed separately ("target build") and the rows
// "align" reuse it: ours NdtTarget / GicpCloud built once; PCL's objects keep their target
// (setInputTarget once; each run calls setInputSource + align, which for GICP includes the source
// covariances, as our GicpCloud(source) does).
//
// The case is built by tests/registration/forest_case.hpp, as in the test (which uses 64 beams
// to stay fast).
//
//   forest_registration_bench [RUNS] [BEAMS]   (defaults 7 and 128; run from the repository root,
//                                               the simulator reads ../shared/data/ouster)
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/ndt.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "../tests/registration/forest_case.hpp"
#include "bench_common.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/preprocess/deskew.hpp"
#include "taiga/preprocess/voxel_filter.hpp"
#include "taiga/registration/gicp.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/registration/voxel_statistics.hpp"
#include "taiga/sim/simulator.hpp"

namespace {

using namespace taiga;
using bench::Clock;
using bench::msSince;
using namespace taiga::test;

pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const Points& points) {
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->reserve(points.size());
  for (const auto& p : points) {
    cloud->push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                   static_cast<float>(p.z())));
  }
  return cloud;
}

struct Measurement {
  double median_ms = 0.0;
  double error_m = 0.0;  ///< of the last run (every run gives the same result)
  double error_deg = 0.0;
  int iterations = 0;
};

Measurement measure(int runs, const lie::SE3& truth,
                    const std::function<std::pair<lie::SE3, int>()>& run) {
  std::vector<double> times;
  Measurement m;
  for (int i = 0; i < runs; ++i) {
    const auto start = Clock::now();
    const auto [T, iterations] = run();
    times.push_back(msSince(start));
    const lie::SE3 delta = truth.inverse() * T;
    m.error_m = delta.translation().norm();
    m.error_deg = delta.rotation().Log().norm() * kDegPerRad;
    m.iterations = iterations;
  }
  std::sort(times.begin(), times.end());
  m.median_ms = times[times.size() / 2];
  return m;
}

double medianTime(int runs, const std::function<void()>& run) {
  std::vector<double> times;
  for (int i = 0; i < runs; ++i) {
    const auto start = Clock::now();
    run();
    times.push_back(msSince(start));
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

void print(const std::string& name, const Measurement& m, double pcl_ms) {
  std::printf("| %-40s | %8.2f | %7.4f | %6.3f | %3d | %7.2fx |\n", name.c_str(), m.median_ms,
              m.error_m, m.error_deg, m.iterations, pcl_ms / m.median_ms);
}

std::string thr(int threads) { return ", " + std::to_string(threads) + " thr"; }

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 7;
  const int beams = argc > 2 ? std::atoi(argv[2]) : 128;
  if (runs < 1 || beams < 1) {
    std::fprintf(stderr, "usage: forest_registration_bench [RUNS] [BEAMS]\n");
    return 2;
  }
  const auto sim_start = Clock::now();
  sim::Scenario scenario = sim::scenarioByName("mixed");
  scenario.lidar.beams = beams;
  scenario.lidar.columns = 1024;
  const sim::Simulation simulation(scenario, 40.0, 7);  // the test's walk, its first place
  const ForestCase c = makeForestCase(simulation, 0);
  const lie::SE3& truth = c.T_world_body;
  std::printf(
      "simulated 'mixed' forest, seed 7, %d beams x 1024 columns (%.1f s to simulate): map of 15"
      " keyframes over %.1f m, %zu points (0.2 m); source %zu points (0.4 m), %.2f m past the"
      " last keyframe; %d runs per row\n",
      beams, msSince(sim_start) / 1000.0, c.keyframe_span_m, c.map_points.size(), c.source.size(),
      c.source_to_last_keyframe_m, runs);

  registration::NdtConfig ndt_config;   // 1 m, DIRECT7, outlier ratio 0.55, 35 iterations
  registration::NdtConfig ndt1_config;  // the same with DIRECT1 (one cell per point)
  ndt1_config.search = registration::NeighbourSearch::kDirect1;
  registration::GicpConfig gicp_config;  // 10 neighbours, 1 m maximum correspondence distance
  const auto pcl_source = toPcl(c.source);
  const auto pcl_map = toPcl(c.map_points);

  // Target builds (once per keyframe in the odometry).
  std::printf("\nTarget builds (median of %d):\n", runs);
  registration::VoxelStatistics stats(1.0);
  stats.add(c.map_points);
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    std::printf("  taiga NdtTarget from VoxelStatistics%s: %.1f ms\n", thr(threads).c_str(),
                medianTime(runs, [&] { const registration::NdtTarget t(stats); }));
    std::printf(
        "  taiga GicpCloud (kd-tree + covariances)%s: %.1f ms\n", thr(threads).c_str(),
        medianTime(runs, [&] { const registration::GicpCloud t(c.map_points, gicp_config); }));
  }
  std::printf("  PCL NDT setInputTarget: %.1f ms\n", medianTime(runs, [&] {
                pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
                ndt.setResolution(1.0f);
                ndt.setInputTarget(pcl_map);
              }));
  const registration::NdtTarget ndt_target(stats);
  const registration::GicpCloud gicp_target(c.map_points, gicp_config);

  // PCL objects with their targets set once.
  pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> pcl_ndt;
  pcl_ndt.setResolution(1.0f);
  pcl_ndt.setOulierRatio(0.55);  // sic, PCL 1.13's spelling
  pcl_ndt.setStepSize(0.1);
  pcl_ndt.setMaximumIterations(35);
  // PCL 1.13 compares the epsilon with the squared translation of the step: 1e-6 = 1 mm.
  pcl_ndt.setTransformationEpsilon(1e-6);
  pcl_ndt.setInputTarget(pcl_map);
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> pcl_gicp;
  pcl_gicp.setCorrespondenceRandomness(10);
  pcl_gicp.setMaxCorrespondenceDistance(1.0);
  pcl_gicp.setMaximumIterations(64);
  pcl_gicp.setTransformationEpsilon(1e-4);
  pcl_gicp.setInputTarget(pcl_map);
  {  // the first align computes and caches PCL's target covariances; time it apart
    const auto start = Clock::now();
    pcl_gicp.setInputSource(pcl_source);
    pcl::PointCloud<pcl::PointXYZ> aligned;
    pcl_gicp.align(aligned, truth.matrix().cast<float>());
    std::printf("  PCL GICP first align (target kd-tree + covariances + align): %.1f ms\n",
                msSince(start));
  }

  struct Guess {
    const char* name;
    lie::SE3 T;
  };
  // Applied on the body side. "odometry": about the error of an IMU prediction; "large": the
  // real-pair benchmark's 0.5 m / 5 deg.
  const Guess guesses[] = {
      {"odometry-like guess: 0.1 m along (1,1,0), 1 deg about (0.3,0.2,1)",
       truth * lie::SE3(lie::SO3::fromAxisAngle({0.3, 0.2, 1.0}, 1.0 * kRadPerDeg),
                        Eigen::Vector3d(1.0, 1.0, 0.0).normalized() * 0.1)},
      {"large guess: 0.5 m along (1,1,0), 5 deg about (0.3,0.2,1)",
       truth * lie::SE3(lie::SO3::fromAxisAngle({0.3, 0.2, 1.0}, 5.0 * kRadPerDeg),
                        Eigen::Vector3d(1.0, 1.0, 0.0).normalized() * 0.5)},
  };
  for (const Guess& g : guesses) {
    const Eigen::Matrix4f guess_f = g.T.matrix().cast<float>();
    std::printf("\n%s (per-scan align, median of %d)\n\n", g.name, runs);
    std::printf("| configuration | median ms | err m | err deg | it | PCL / this |\n");
    std::printf("|---|---|---|---|---|---|\n");
    const Measurement pcl_ndt_m = measure(runs, truth, [&] {
      pcl_ndt.setInputSource(pcl_source);
      pcl::PointCloud<pcl::PointXYZ> aligned;
      pcl_ndt.align(aligned, guess_f);
      return std::pair{lie::SE3::fromMatrix(pcl_ndt.getFinalTransformation().cast<double>()),
                       pcl_ndt.getFinalNumIteration()};
    });
    print("PCL NDT", pcl_ndt_m, pcl_ndt_m.median_ms);
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      print("taiga NDT DIRECT1" + thr(threads),
            measure(runs, truth,
                    [&] {
                      const auto r = registration::alignNdt(c.source, ndt_target, g.T, ndt1_config);
                      return std::pair{r.T_target_source, r.iterations};
                    }),
            pcl_ndt_m.median_ms);
      print("taiga NDT DIRECT7" + thr(threads),
            measure(runs, truth,
                    [&] {
                      const auto r = registration::alignNdt(c.source, ndt_target, g.T, ndt_config);
                      return std::pair{r.T_target_source, r.iterations};
                    }),
            pcl_ndt_m.median_ms);
      print("taiga D2D-NDT" + thr(threads),
            measure(runs, truth,
                    [&] {
                      const auto r =
                          registration::alignD2dNdt(c.source, ndt_target, g.T, ndt_config);
                      return std::pair{r.T_target_source, r.iterations};
                    }),
            pcl_ndt_m.median_ms);
    }
    const Measurement pcl_gicp_m = measure(runs, truth, [&] {
      pcl_gicp.setInputSource(pcl_source);
      pcl::PointCloud<pcl::PointXYZ> aligned;
      pcl_gicp.align(aligned, guess_f);
      return std::pair{lie::SE3::fromMatrix(pcl_gicp.getFinalTransformation().cast<double>()),
                       pcl_gicp.nr_iterations_};
    });
    print("PCL GICP (source covariances + align)", pcl_gicp_m, pcl_gicp_m.median_ms);
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      print("taiga GICP (source covariances + align)" + thr(threads),
            measure(runs, truth,
                    [&] {
                      const registration::GicpCloud source(c.source, gicp_config);
                      const auto r = registration::alignGicp(source, gicp_target, g.T, gicp_config);
                      return std::pair{r.T_target_source, r.iterations};
                    }),
            pcl_gicp_m.median_ms);
    }
  }
  return 0;
}
