// P2D-NDT and D2D-NDT: analytic derivatives against numerical differentiation, the mixture
// constants, forward/inverse agreement, determinism over thread counts, degenerate input.
#include "taiga/registration/ndt.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

#include "registration_data.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration {
namespace {

using test::kRegistrationData;

struct Data {
  std::vector<Eigen::Vector3d> source, target, source_down;
  lie::SE3 T_target_source;
};

const Data& data() {
  static const Data d = [] {
    Data out;
    out.source = test::loadPositions(kRegistrationData / "source.ply");
    out.target = test::loadPositions(kRegistrationData / "target.ply");
    out.source_down = voxelDownsample(out.source, 0.4);
    out.T_target_source = test::loadTransform(kRegistrationData / "T_target_source.txt");
    return out;
  }();
  return d;
}

TEST(Ndt, ConstantsMatchMagnusson) {
  // PCL 1.13 and ndt_omp give these for 1 m cells and outlier ratio 0.55.
  const NdtConstants k = ndtConstants(1.0, 0.55);
  // By hand: c1 = 4.5, c2 = 0.55, d3 = -log(c2); d1 = -log(c1 + c2) - d3,
  // d2 = -2 log((-log(c1 exp(-1/2) + c2) - d3) / d1).
  EXPECT_NEAR(k.d1, -2.2172, 1e-4);
  EXPECT_NEAR(k.d2, 0.4332, 1e-3);
  EXPECT_LT(k.d1, 0.0);
  EXPECT_GT(k.d2, 0.0);
  EXPECT_NEAR(k.d1, -std::log(4.5 + 0.55) + std::log(0.55), 1e-12);
}

// Source points whose DIRECT7 neighbourhood cannot change within the finite-difference steps:
// closer than 15 m and at least 0.1 m from every cell face at T.
std::vector<Eigen::Vector3d> stablePoints(const lie::SE3& T, double resolution_m) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& x : data().source_down) {
    if (x.norm() > 15.0) continue;
    const Eigen::Vector3d s = (T * x) / resolution_m;
    const Eigen::Vector3d frac = s - s.array().floor().matrix();
    if ((frac.array() > 0.1 / resolution_m).all() &&
        (frac.array() < 1 - 0.1 / resolution_m).all()) {
      out.push_back(x);
    }
  }
  return out;
}

TEST(Ndt, TheNeighbourCacheGivesTheSameDerivativesAsLookingEveryCellUp) {
  // Poses a few centimetres to decimetres apart, as Newton steps are: some points stay in their
  // voxel (cached cells), some move on (looked up again), with one neighbour or seven.
  const NdtTarget target = NdtTarget::fromPoints(data().target, 1.0);
  std::mt19937 rng(3);
  for (const NeighbourSearch search : {NeighbourSearch::kDirect1, NeighbourSearch::kDirect7}) {
    NdtConfig config;
    config.search = search;
    NeighbourCache cache(data().source.size());
    lie::SE3 T = data().T_target_source;
    for (int step = 0; step < 6; ++step) {
      T = T * test::randomPerturbation(rng, step < 3 ? 0.02 : 0.3, step < 3 ? 0.2 : 2.0);
      const NdtDerivatives looked_up = ndtDerivatives(data().source, target, T, config);
      const NdtDerivatives cached = ndtDerivatives(data().source, target, T, config, true, &cache);
      EXPECT_EQ(cached.score, looked_up.score);
      EXPECT_EQ(cached.gradient, looked_up.gradient);
      EXPECT_EQ(cached.hessian, looked_up.hessian);
      EXPECT_EQ(cached.num_inliers, looked_up.num_inliers);
    }
  }
}

TEST(Ndt, AnalyticGradientAndHessianMatchNumericalDifferentiation) {
  NdtConfig config;
  const NdtTarget target = NdtTarget::fromPoints(data().target, 1.0);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 3; ++trial) {
    const lie::SE3 T = data().T_target_source * test::randomPerturbation(rng, 0.3, 3.0);
    const auto points = stablePoints(T, 1.0);
    ASSERT_GT(points.size(), 300u);
    const NdtDerivatives D = ndtDerivatives(points, target, T, config);
    ASSERT_GT(D.num_inliers, 300u);
    auto f = [&](const lie::Vector6& tau) {
      return ndtDerivatives(points, target, T.plus(tau), config, false).score;
    };
    const double h = 1e-5;
    lie::Vector6 g_num;
    lie::Matrix6 H_num;
    for (int i = 0; i < 6; ++i) {
      const lie::Vector6 ei = lie::Vector6::Unit(i) * h;
      g_num(i) = (f(ei) - f(-ei)) / (2 * h);
      for (int j = 0; j < 6; ++j) {
        const lie::Vector6 ej = lie::Vector6::Unit(j) * h;
        H_num(i, j) = (f(ei + ej) - f(ei - ej) - f(-ei + ej) + f(-ei - ej)) / (4 * h * h);
      }
    }
    EXPECT_LT((D.gradient - g_num).norm(), 1e-5 * D.gradient.norm() + 1e-6)
        << D.gradient.transpose() << "\n"
        << g_num.transpose();
    EXPECT_LT((D.hessian - H_num).norm(), 1e-3 * D.hessian.norm()) << D.hessian << "\n\n" << H_num;
    // The second-derivative term of the point matters: without it the check above would fail.
    EXPECT_GT(D.hessian.norm(), 1.0);
  }
}

TEST(Ndt, ForwardAndInverseRegistrationsAgree) {
  NdtConfig config;
  config.coarse_resolutions_m = {2.0};
  const auto target_down = voxelDownsample(data().target, 0.4);
  std::mt19937 rng(3);
  const lie::SE3 guess = data().T_target_source * test::randomPerturbation(rng, 0.5, 5.0);
  const RegistrationResult forward = alignNdt(data().source_down, data().target, guess, config);
  const RegistrationResult inverse = alignNdt(target_down, data().source, guess.inverse(), config);
  ASSERT_TRUE(forward.converged) << forward.reason;
  ASSERT_TRUE(inverse.converged) << inverse.reason;
  const test::PoseError e =
      test::poseError(forward.T_target_source * inverse.T_target_source, lie::SE3());
  EXPECT_LT(e.translation_m, 0.03);
  EXPECT_LT(e.rotation_deg, 0.3);
  std::printf("forward * inverse: %.4f m, %.3f deg\n", e.translation_m, e.rotation_deg);
}

template <class Align>
void expectBitIdenticalOverThreadCounts(const Align& align) {
  RegistrationResult one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = align();
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = align();
  }
  EXPECT_TRUE(one.converged) << one.reason;
  EXPECT_EQ(one.T_target_source.matrix(), two.T_target_source.matrix());
  EXPECT_EQ(one.hessian, two.hessian);
  EXPECT_EQ(one.cost, two.cost);
  EXPECT_EQ(one.iterations, two.iterations);
}

TEST(Ndt, OneAndTwoThreadsGiveBitIdenticalResults) {
  NdtConfig config;
  const NdtTarget target = NdtTarget::fromPoints(data().target, 1.0);
  std::mt19937 rng(11);
  const lie::SE3 guess = data().T_target_source * test::randomPerturbation(rng, 0.5, 5.0);
  expectBitIdenticalOverThreadCounts(
      [&] { return alignNdt(data().source_down, target, guess, config); });
  expectBitIdenticalOverThreadCounts(
      [&] { return alignD2dNdt(data().source, target, guess, config); });
}

TEST(Ndt, NeighbourSearchDirect1AlsoConverges) {
  NdtConfig config;
  config.search = NeighbourSearch::kDirect1;
  config.coarse_resolutions_m = {2.0};
  std::mt19937 rng(13);
  const lie::SE3 guess = data().T_target_source * test::randomPerturbation(rng, 0.3, 3.0);
  const RegistrationResult r = alignNdt(data().source_down, data().target, guess, config);
  ASSERT_TRUE(r.converged) << r.reason;
  const test::PoseError e = test::poseError(r.T_target_source, data().T_target_source);
  EXPECT_LT(e.translation_m, 0.05);
  EXPECT_LT(e.rotation_deg, 0.5);
}

TEST(Ndt, RegistrationAgainstAnIncrementalMapEqualsAFreshMap) {
  // The target added in two halves, plus a "keyframe" (the source, shifted) added and removed:
  // the NDT target and the registration are bit-identical to those from the target alone.
  const auto& target = data().target;
  const std::size_t half = target.size() / 2;
  VoxelStatistics map(1.0);
  map.add(std::span(target).subspan(half));
  std::vector<Eigen::Vector3d> keyframe = data().source;
  for (auto& p : keyframe) p += Eigen::Vector3d(0.3, -0.2, 0.1);
  map.add(keyframe);
  map.add(std::span(target).first(half));
  map.remove(keyframe);
  const NdtTarget incremental(map);
  const NdtTarget fresh = NdtTarget::fromPoints(target, 1.0);
  const NdtConfig config;
  std::mt19937 rng(17);
  const lie::SE3 guess = data().T_target_source * test::randomPerturbation(rng, 0.3, 3.0);
  const RegistrationResult a = alignNdt(data().source_down, incremental, guess, config);
  const RegistrationResult b = alignNdt(data().source_down, fresh, guess, config);
  ASSERT_TRUE(a.converged) << a.reason;
  EXPECT_EQ(a.T_target_source.matrix(), b.T_target_source.matrix());
  EXPECT_EQ(a.iterations, b.iterations);
  const test::PoseError e = test::poseError(a.T_target_source, data().T_target_source);
  EXPECT_LT(e.translation_m, 0.05);
  EXPECT_LT(e.rotation_deg, 0.5);
}

// A flat 20 m x 20 m grid of points at z = 0.
std::vector<Eigen::Vector3d> plane() {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) out.emplace_back(-10.0 + 0.2 * i, -10.0 + 0.2 * j, 0.0);
  }
  return out;
}

TEST(Ndt, DegenerateInputIsReportedNotCrashedOn) {
  const NdtConfig config;
  const std::vector<Eigen::Vector3d> empty;
  const std::vector<Eigen::Vector3d> few(data().source.begin(), data().source.begin() + 5);
  const auto flat = plane();
  const lie::SE3 guess;
  using Fn =
      RegistrationResult (*)(std::span<const Eigen::Vector3d>, std::span<const Eigen::Vector3d>,
                             const lie::SE3&, const NdtConfig&);
  for (const Fn fn : {static_cast<Fn>(&alignNdt), static_cast<Fn>(&alignD2dNdt)}) {
    const RegistrationResult e1 = fn(empty, data().target, guess, config);
    EXPECT_FALSE(e1.converged);
    EXPECT_NE(e1.reason.find("source cloud is empty"), std::string::npos) << e1.reason;
    const RegistrationResult e2 = fn(data().source_down, empty, guess, config);
    EXPECT_FALSE(e2.converged);
    EXPECT_NE(e2.reason.find("target cloud is empty"), std::string::npos) << e2.reason;
    const RegistrationResult e3 = fn(few, data().target, guess, config);
    EXPECT_FALSE(e3.converged);
    EXPECT_NE(e3.reason.find("too few points"), std::string::npos) << e3.reason;
    const RegistrationResult e4 = fn(flat, flat, guess, config);
    EXPECT_FALSE(e4.converged);
    EXPECT_NE(e4.reason.find("planar"), std::string::npos) << e4.reason;
    // No overlap at all: the source 1 km away.
    const RegistrationResult e5 =
        fn(data().source_down, data().target, lie::SE3(lie::SO3(), {1000.0, 0.0, 0.0}), config);
    EXPECT_FALSE(e5.converged);
    EXPECT_FALSE(e5.reason.empty());
  }
}

TEST(Ndt, InvalidConfigurationNamesTheField) {
  NdtConfig config;
  config.resolution_m = -1.0;
  try {
    config.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("resolution_m"), std::string::npos);
  }
}

}  // namespace
}  // namespace taiga::registration
