// Cost of the Lie-group operations that run per point or per IMU sample (deskewing interpolates
// one SE(3) pose per lidar column, preintegration calls Exp and Jr per IMU sample), each next to
// the Eigen expression it replaces, so the ratio is what BENCHMARK.md records.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "taiga/lie/se3.hpp"

namespace {

using taiga::lie::SE3;
using taiga::lie::SO3;

std::vector<Eigen::Vector3d> randomVectors(double scale) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-scale, scale);
  std::vector<Eigen::Vector3d> out(1024);
  for (auto& v : out) v = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return out;
}

void BM_SO3Exp(benchmark::State& state) {
  const auto thetas = randomVectors(1.5);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(SO3::Exp(thetas[i++ & 1023]));
}

void BM_EigenAngleAxisToQuaternion(benchmark::State& state) {
  const auto thetas = randomVectors(1.5);
  std::size_t i = 0;
  for (auto _ : state) {
    const Eigen::Vector3d& t = thetas[i++ & 1023];
    benchmark::DoNotOptimize(Eigen::Quaterniond(Eigen::AngleAxisd(t.norm(), t.normalized())));
  }
}

void BM_SO3ExpWithRightJacobian(benchmark::State& state) {
  const auto thetas = randomVectors(1.5);
  std::size_t i = 0;
  Eigen::Matrix3d J;
  for (auto _ : state) {
    benchmark::DoNotOptimize(SO3::Exp(thetas[i++ & 1023], &J));
    benchmark::DoNotOptimize(J);
  }
}

void BM_SE3Interpolate(benchmark::State& state) {
  const auto a = randomVectors(1.0), b = randomVectors(5.0);
  std::vector<SE3> poses;
  for (std::size_t k = 0; k < a.size(); ++k) poses.emplace_back(SO3::Exp(a[k]), b[k]);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(taiga::lie::interpolate(poses[i & 1023], poses[(i + 1) & 1023], 0.3));
    ++i;
  }
}

void BM_EigenSlerpAndLerp(benchmark::State& state) {
  const auto a = randomVectors(1.0), b = randomVectors(5.0);
  std::vector<Eigen::Quaterniond> q;
  for (const auto& t : a) q.emplace_back(Eigen::AngleAxisd(t.norm(), t.normalized()));
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t j = i & 1023, k = (i + 1) & 1023;
    benchmark::DoNotOptimize(q[j].slerp(0.3, q[k]));
    benchmark::DoNotOptimize(Eigen::Vector3d(0.7 * b[j] + 0.3 * b[k]));
    ++i;
  }
}

void BM_SE3TransformPoint(benchmark::State& state) {
  const SE3 T(SO3::Exp(Eigen::Vector3d(0.1, 0.2, 0.3)), Eigen::Vector3d(1, 2, 3));
  const auto points = randomVectors(30.0);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(T * points[i++ & 1023]);
}

void BM_EigenIsometryTransformPoint(benchmark::State& state) {
  const Eigen::Isometry3d T =
      SE3(SO3::Exp(Eigen::Vector3d(0.1, 0.2, 0.3)), Eigen::Vector3d(1, 2, 3)).isometry();
  const auto points = randomVectors(30.0);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(T * points[i++ & 1023]);
}

BENCHMARK(BM_SO3Exp);
BENCHMARK(BM_EigenAngleAxisToQuaternion);
BENCHMARK(BM_SO3ExpWithRightJacobian);
BENCHMARK(BM_SE3Interpolate);
BENCHMARK(BM_EigenSlerpAndLerp);
BENCHMARK(BM_SE3TransformPoint);
BENCHMARK(BM_EigenIsometryTransformPoint);

}  // namespace
