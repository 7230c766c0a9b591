// Geometric degeneracy that the planarity check cannot see: a corridor (floor and two walls)
// leaves the translation along it unconstrained. Every method must report it, not return a
// silently wrong pose; the planarity ratio and the condition numbers are checked too.
#include "taiga/registration/degeneracy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "taiga/registration/registration.hpp"

namespace taiga::registration {
namespace {

// 40 m long, 4 m wide, 3 m high, along x; 1 cm noise.
std::vector<Eigen::Vector3d> corridor(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 20000; ++i) {
    const double x = -20.0 + 40.0 * u(rng);
    switch (i % 3) {
      case 0:
        points.emplace_back(x, -2.0 + 4.0 * u(rng), noise(rng));
        break;
      case 1:
        points.emplace_back(x, -2.0 + noise(rng), 3.0 * u(rng));
        break;
      default:
        points.emplace_back(x, 2.0 + noise(rng), 3.0 * u(rng));
    }
  }
  return points;
}

TEST(Degeneracy, ACorridorIsReportedByEveryMethod) {
  const auto source = corridor(1);
  const auto target = corridor(2);
  // Not planar (0.0075, far above the 1e-6 of the planarity check), so that check misses it.
  EXPECT_GT(planarityRatio(source), 1e-3);
  const lie::SE3 guess(lie::SO3(), Eigen::Vector3d(0.3, 0.1, 0.05));
  for (Method method : {Method::kNdt, Method::kD2dNdt, Method::kGicp}) {
    RegistrationConfig config;
    config.method = method;
    const RegistrationResult r = registerClouds(source, target, guess, config);
    EXPECT_FALSE(r.converged) << methodName(method);
    EXPECT_GT(r.translation_condition, config.ndt.max_translation_condition) << methodName(method);
    EXPECT_FALSE(r.reason.empty()) << methodName(method);
    // The direction the data does not constrain is x, along the corridor: y and z are found.
    EXPECT_LT(std::abs(r.T_target_source.translation().y()), 0.02) << methodName(method);
    EXPECT_LT(std::abs(r.T_target_source.translation().z()), 0.02) << methodName(method);
  }
}

TEST(Degeneracy, ConditionNumbers) {
  lie::Matrix6 H = lie::Matrix6::Identity();
  H(0, 0) = 100.0;
  H(5, 5) = 0.5;
  EXPECT_DOUBLE_EQ(conditionNumber(H), 200.0);
  EXPECT_DOUBLE_EQ(translationConditionNumber(H), 100.0);
  H(1, 1) = -1.0;
  EXPECT_TRUE(std::isinf(conditionNumber(H)));
  EXPECT_TRUE(std::isinf(translationConditionNumber(H)));
}

TEST(Degeneracy, PlanarityRatio) {
  std::vector<Eigen::Vector3d> plane;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) plane.emplace_back(i, j, 0.5 * i);
  }
  EXPECT_LT(planarityRatio(plane), 1e-12);
  EXPECT_TRUE(inputProblem(plane, "source", 10, 1e-6).has_value());
  plane.emplace_back(0.0, 0.0, 5.0);
  EXPECT_GT(planarityRatio(plane), 1e-4);
  EXPECT_FALSE(inputProblem(plane, "source", 10, 1e-6).has_value());
  plane.emplace_back(std::nan(""), 0.0, 0.0);
  const auto problem = inputProblem(plane, "source", 10, 1e-6);
  ASSERT_TRUE(problem.has_value());
  EXPECT_NE(problem->find("1 non-finite points"), std::string::npos) << *problem;
}

}  // namespace
}  // namespace taiga::registration
