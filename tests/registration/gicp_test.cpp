// GICP: per-point covariances, forward/inverse agreement, determinism over thread counts,
// degenerate input, and the fitness score.
#include "taiga/registration/gicp.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <random>
#include <vector>

#include "registration_data.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/registration/kdtree.hpp"
#include "taiga/registration/registration.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration {
namespace {

using test::kRegistrationData;

struct Data {
  std::vector<Eigen::Vector3d> source, target;
  lie::SE3 T_target_source;
};

const Data& data() {
  static const Data d = [] {
    Data out;
    out.source = voxelDownsample(test::loadPositions(kRegistrationData / "source.ply"), 0.2);
    out.target = voxelDownsample(test::loadPositions(kRegistrationData / "target.ply"), 0.2);
    out.T_target_source = test::loadTransform(kRegistrationData / "T_target_source.txt");
    return out;
  }();
  return d;
}

TEST(Gicp, CovariancesArePlanesWithTheConfiguredThickness) {
  // Points on the plane z = 2 x: every covariance has the plane normal as its eigenvector with
  // eigenvalue covariance_epsilon.
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) points.emplace_back(0.1 * i, 0.1 * j, 0.2 * i);
  }
  const GicpConfig config;
  const GicpCloud cloud(points, config);
  const Eigen::Vector3d normal = Eigen::Vector3d(2.0, 0.0, -1.0).normalized();
  for (const auto& C : cloud.covariances()) {
    EXPECT_NEAR(normal.dot(C * normal), config.covariance_epsilon, 1e-9);
    EXPECT_NEAR(C.trace(), 2.0 + config.covariance_epsilon, 1e-9);
  }
}

TEST(Gicp, ForwardAndInverseRegistrationsAgree) {
  const GicpConfig config;
  std::mt19937 rng(21);
  const lie::SE3 guess = data().T_target_source * test::randomPerturbation(rng, 0.5, 5.0);
  const RegistrationResult forward = alignGicp(data().source, data().target, guess, config);
  const RegistrationResult inverse =
      alignGicp(data().target, data().source, guess.inverse(), config);
  ASSERT_TRUE(forward.converged) << forward.reason;
  ASSERT_TRUE(inverse.converged) << inverse.reason;
  const test::PoseError e =
      test::poseError(forward.T_target_source * inverse.T_target_source, lie::SE3());
  std::printf("forward * inverse: %.4f m, %.3f deg\n", e.translation_m, e.rotation_deg);
  EXPECT_LT(e.translation_m, 0.03);
  EXPECT_LT(e.rotation_deg, 0.3);
}

TEST(Gicp, OneAndTwoThreadsGiveBitIdenticalResults) {
  const GicpConfig config;
  std::mt19937 rng(22);
  const lie::SE3 guess = data().T_target_source * test::randomPerturbation(rng, 0.5, 5.0);
  RegistrationResult one, two;
  double fitness_one = 0.0, fitness_two = 0.0;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = alignGicp(data().source, data().target, guess, config);
    fitness_one = fitnessScore(data().source, KdTree(data().target), one.T_target_source);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = alignGicp(data().source, data().target, guess, config);
    fitness_two = fitnessScore(data().source, KdTree(data().target), two.T_target_source);
  }
  EXPECT_TRUE(one.converged) << one.reason;
  EXPECT_EQ(one.T_target_source.matrix(), two.T_target_source.matrix());
  EXPECT_EQ(one.hessian, two.hessian);
  EXPECT_EQ(fitness_one, fitness_two);
}

TEST(Gicp, DegenerateInputIsReportedNotCrashedOn) {
  const GicpConfig config;
  const std::vector<Eigen::Vector3d> empty;
  const std::vector<Eigen::Vector3d> few(data().source.begin(), data().source.begin() + 4);
  std::vector<Eigen::Vector3d> plane;
  for (int i = 0; i < 50; ++i) {
    for (int j = 0; j < 50; ++j) plane.emplace_back(0.2 * i, 0.2 * j, 0.0);
  }
  const lie::SE3 guess;
  const RegistrationResult e1 = alignGicp(empty, data().target, guess, config);
  EXPECT_FALSE(e1.converged);
  EXPECT_NE(e1.reason.find("source cloud is empty"), std::string::npos) << e1.reason;
  const RegistrationResult e2 = alignGicp(few, data().target, guess, config);
  EXPECT_FALSE(e2.converged);
  EXPECT_NE(e2.reason.find("too few points"), std::string::npos) << e2.reason;
  const RegistrationResult e3 = alignGicp(plane, plane, guess, config);
  EXPECT_FALSE(e3.converged);
  EXPECT_NE(e3.reason.find("planar"), std::string::npos) << e3.reason;
  const RegistrationResult e4 =
      alignGicp(data().source, data().target, lie::SE3(lie::SO3(), {500.0, 0.0, 0.0}), config);
  EXPECT_FALSE(e4.converged);
  EXPECT_NE(e4.reason.find("too few correspondences"), std::string::npos) << e4.reason;
}

TEST(Fitness, IsTheMeanSquaredDistanceToTheClosestTargetPoint) {
  const std::vector<Eigen::Vector3d> target = {{0, 0, 0}, {10, 0, 0}};
  const std::vector<Eigen::Vector3d> source = {{1, 0, 0}, {7, 0, 0}};
  const KdTree tree(target);
  EXPECT_DOUBLE_EQ(fitnessScore(source, tree, lie::SE3()), (1.0 + 9.0) / 2.0);
  // Moved by +1 m in x: distances 2 and 2.
  EXPECT_DOUBLE_EQ(fitnessScore(source, tree, lie::SE3(lie::SO3(), {1.0, 0.0, 0.0})), 4.0);
  EXPECT_DOUBLE_EQ(fitnessScore(source, tree, lie::SE3(), 2.0), 1.0);  // 3 m is beyond 2 m
}

TEST(KdTree, NearestWithinARadiusIsTheNearestPointWhenItLiesWithin) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coordinate(-10.0, 10.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 5000; ++i) points.emplace_back(coordinate(rng), coordinate(rng), 0.0);
  const KdTree tree(points);
  int within = 0, beyond = 0;
  for (int q = 0; q < 2000; ++q) {
    // Queries off the plane, some farther from it than the radius.
    const Eigen::Vector3d query(coordinate(rng), coordinate(rng), 0.1 * coordinate(rng));
    std::size_t nearest = 0, bounded = 0;
    double nearest_sq = 0.0, bounded_sq = 0.0;
    ASSERT_TRUE(tree.nearest(query, nearest, nearest_sq));
    const double radius_m = 0.5;
    // A hint (any point: near, far, the nearest itself) only shortens the search.
    const std::size_t hint = q % 3 == 0 ? nearest : static_cast<std::size_t>(rng() % points.size());
    std::size_t hinted = 0;
    double hinted_sq = 0.0;
    const bool hinted_found = tree.nearestWithin(query, radius_m, hinted, hinted_sq, hint);
    if (tree.nearestWithin(query, radius_m, bounded, bounded_sq)) {
      ++within;
      EXPECT_EQ(bounded, nearest);
      EXPECT_EQ(bounded_sq, nearest_sq);
      EXPECT_LE(bounded_sq, radius_m * radius_m);
      ASSERT_TRUE(hinted_found);
      EXPECT_EQ(hinted_sq, nearest_sq);
    } else {
      EXPECT_FALSE(hinted_found);
      ++beyond;
      EXPECT_GT(nearest_sq, radius_m * radius_m);
    }
  }
  EXPECT_GT(within, 100);
  EXPECT_GT(beyond, 100);
  // Inclusive at the radius; nothing in an empty tree.
  std::size_t index = 0;
  double sq = 0.0;
  EXPECT_TRUE(KdTree(std::vector<Eigen::Vector3d>{{1, 0, 0}})
                  .nearestWithin(Eigen::Vector3d::Zero(), 1.0, index, sq));
  EXPECT_FALSE(KdTree(std::vector<Eigen::Vector3d>{}).nearestWithin({0, 0, 0}, 1.0, index, sq));
}

TEST(Registration, FacadeFillsTheFitnessScore) {
  RegistrationConfig config;
  config.method = Method::kGicp;
  // A gross initial error (1 m, 10 deg about z): the fitness drops at the solution. (From small
  // errors it need not: on this pair the points without overlap dominate the mean, and a pose
  // 1 deg off scored 0.326 m^2 against 0.347 m^2 at the solution.)
  const lie::SE3 guess =
      data().T_target_source * lie::SE3(lie::SO3::fromAxisAngle({0, 0, 1}, 10.0 * kRadPerDeg),
                                        Eigen::Vector3d(1.0, 0.0, 0.0));
  const RegistrationResult r = registerClouds(data().source, data().target, guess, config);
  ASSERT_TRUE(r.converged) << r.reason;
  const KdTree tree(data().target);
  EXPECT_EQ(r.fitness_m2, fitnessScore(data().source, tree, r.T_target_source));
  EXPECT_LT(r.fitness_m2, 0.8 * fitnessScore(data().source, tree, guess));
  EXPECT_EQ(methodFromName("d2d"), Method::kD2dNdt);
  EXPECT_EQ(methodFromName("icp"), std::nullopt);
}

}  // namespace
}  // namespace taiga::registration
