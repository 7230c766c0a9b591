// Registration benchmark: our NDT and GICP against PCL 1.13's NormalDistributionsTransform and
// GeneralizedIterativeClosestPoint, on the same clouds, from the same initial guess, in the same
// process. Prints per configuration the median time over the runs, the error against the
// reference transform, and the ratio PCL / taiga. Plain timing main (the runs are long enough that
// Google Benchmark's statistics add nothing), results go to bench/BENCHMARK.md.
//
//   registration_bench [DATA_DIR] [RUNS]   (DATA_DIR defaults to ../shared/data/registration)
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/ndt.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/registration/gicp.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace {

using namespace taiga;
using Clock = std::chrono::steady_clock;
using Points = std::vector<Eigen::Vector3d>;

lie::SE3 loadTransform(const std::filesystem::path& path) {
  std::ifstream in(path);
  Eigen::Matrix4d T;
  for (int i = 0; i < 16; ++i) in >> T(i / 4, i % 4);
  if (!in) {
    std::fprintf(stderr, "%s: expected a 4x4 matrix\n", path.c_str());
    std::exit(2);
  }
  return lie::SE3::fromMatrix(T);
}

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
  double error_m = 0.0;
  double error_deg = 0.0;
  int iterations = 0;
};

// Runs `run` `runs` times; it returns the estimate and the number of iterations.
Measurement measure(int runs, const lie::SE3& reference,
                    const std::function<std::pair<lie::SE3, int>()>& run) {
  std::vector<double> times;
  Measurement m;
  for (int i = 0; i < runs; ++i) {
    const auto start = Clock::now();
    const auto [T, iterations] = run();
    times.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    const lie::SE3 delta = reference.inverse() * T;
    m.error_m = delta.translation().norm();
    m.error_deg = delta.rotation().Log().norm() * kDegPerRad;
    m.iterations = iterations;
  }
  std::sort(times.begin(), times.end());
  m.median_ms = times[times.size() / 2];
  return m;
}

void print(const char* name, const Measurement& m, double reference_ms) {
  std::printf("| %-44s | %9.2f | %7.4f | %6.3f | %3d | %6.2fx |\n", name, m.median_ms, m.error_m,
              m.error_deg, m.iterations, reference_ms / m.median_ms);
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : "../shared/data/registration";
  const int runs = argc > 2 ? std::atoi(argv[2]) : 7;
  const Points source_raw = io::readPointCloudFile(dir / "source.ply", 0.0).cloud.positions;
  const Points target_raw = io::readPointCloudFile(dir / "target.ply", 0.0).cloud.positions;
  const lie::SE3 reference = loadTransform(dir / "T_target_source.txt");
  // The same initial error for every method: 0.5 m along (1, 1, 0)/sqrt 2 and 5 deg about
  // (0.3, 0.2, 1) normalized, applied on the source side.
  const lie::SE3 guess =
      reference * lie::SE3(lie::SO3::fromAxisAngle({0.3, 0.2, 1.0}, 5.0 * kRadPerDeg),
                           Eigen::Vector3d(1.0, 1.0, 0.0).normalized() * 0.5);
  const Eigen::Matrix4f guess_f = guess.matrix().cast<float>();

  // NDT: source voxelized at 0.4 m (the pipeline's registration source), full target, 1 m cells.
  const Points ndt_source = registration::voxelDownsample(source_raw, 0.4);
  // GICP: both clouds voxelized at 0.2 m, 10 neighbours for the covariances, 1 m max distance.
  const Points gicp_source = registration::voxelDownsample(source_raw, 0.2);
  const Points gicp_target = registration::voxelDownsample(target_raw, 0.2);
  std::printf(
      "source %zu points, target %zu points; NDT source %zu, GICP source/target %zu/%zu;"
      " %d runs\n\n",
      source_raw.size(), target_raw.size(), ndt_source.size(), gicp_source.size(),
      gicp_target.size(), runs);

  registration::NdtConfig ndt_config;  // 1 m, DIRECT7, outlier ratio 0.55, 35 iterations
  registration::GicpConfig gicp_config;

  // PCL NDT: same cell size, outlier ratio and iteration cap; TransformationEpsilon 1e-6 because
  // PCL 1.13 compares it with the squared translation of the step (so 1e-6 stops below 1 mm, our
  // step_epsilon_m); its default 0.1 stops after the first iteration on this pair.
  const auto pcl_ndt_source = toPcl(ndt_source);
  const auto pcl_ndt_target = toPcl(target_raw);
  const Measurement pcl_ndt = measure(runs, reference, [&] {
    pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
    ndt.setResolution(1.0f);
    ndt.setOulierRatio(0.55);  // sic, PCL 1.13's spelling
    ndt.setStepSize(0.1);
    ndt.setMaximumIterations(35);
    ndt.setTransformationEpsilon(1e-6);
    ndt.setInputTarget(pcl_ndt_target);
    ndt.setInputSource(pcl_ndt_source);
    pcl::PointCloud<pcl::PointXYZ> aligned;
    ndt.align(aligned, guess_f);
    return std::pair{lie::SE3::fromMatrix(ndt.getFinalTransformation().cast<double>()),
                     ndt.getFinalNumIteration()};
  });
  const auto pcl_gicp_source = toPcl(gicp_source);
  const auto pcl_gicp_target = toPcl(gicp_target);
  const Measurement pcl_gicp = measure(runs, reference, [&] {
    pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
    gicp.setCorrespondenceRandomness(10);
    gicp.setMaxCorrespondenceDistance(1.0);
    gicp.setMaximumIterations(64);
    gicp.setTransformationEpsilon(1e-4);
    gicp.setInputTarget(pcl_gicp_target);
    gicp.setInputSource(pcl_gicp_source);
    pcl::PointCloud<pcl::PointXYZ> aligned;
    gicp.align(aligned, guess_f);
    return std::pair{lie::SE3::fromMatrix(gicp.getFinalTransformation().cast<double>()),
                     gicp.nr_iterations_};
  });

  std::printf("| configuration | median ms | err m | err deg | it | PCL / this |\n");
  std::printf("|---|---|---|---|---|---|\n");
  print("PCL NDT (target build + align)", pcl_ndt, pcl_ndt.median_ms);
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    const Measurement ours = measure(runs, reference, [&] {
      const auto target = registration::NdtTarget::fromPoints(target_raw, 1.0);
      const auto r = registration::alignNdt(ndt_source, target, guess, ndt_config);
      return std::pair{r.T_target_source, r.iterations};
    });
    const std::string name =
        "taiga NDT DIRECT7 (target build + align), " + std::to_string(threads) + " thr";
    print(name.c_str(), ours, pcl_ndt.median_ms);
    const auto target = registration::NdtTarget::fromPoints(target_raw, 1.0);
    const Measurement align_only = measure(runs, reference, [&] {
      const auto r = registration::alignNdt(ndt_source, target, guess, ndt_config);
      return std::pair{r.T_target_source, r.iterations};
    });
    print(("taiga NDT DIRECT7 (align only), " + std::to_string(threads) + " thr").c_str(),
          align_only, pcl_ndt.median_ms);
    const Measurement d2d = measure(runs, reference, [&] {
      const auto r = registration::alignD2dNdt(ndt_source, target, guess, ndt_config);
      return std::pair{r.T_target_source, r.iterations};
    });
    print(("taiga D2D-NDT (align only), " + std::to_string(threads) + " thr").c_str(), d2d,
          pcl_ndt.median_ms);
  }
  print("PCL GICP (covariances + align)", pcl_gicp, pcl_gicp.median_ms);
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    const Measurement ours = measure(runs, reference, [&] {
      const registration::GicpCloud source(gicp_source, gicp_config);
      const registration::GicpCloud target(gicp_target, gicp_config);
      const auto r = registration::alignGicp(source, target, guess, gicp_config);
      return std::pair{r.T_target_source, r.iterations};
    });
    print(("taiga GICP (covariances + align), " + std::to_string(threads) + " thr").c_str(), ours,
          pcl_gicp.median_ms);
  }
  return 0;
}
