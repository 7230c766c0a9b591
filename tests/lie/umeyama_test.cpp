// Point-set alignment: exact recovery of a known transform, agreement with Umeyama's closed form
// on noisy points (the formulas of lie/umeyama.hpp written out), a rotation even where a
// reflection fits better, and the rank test that refuses points on a line.
#include "taiga/lie/umeyama.hpp"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <random>
#include <vector>

namespace taiga::lie {
namespace {

/// Umeyama's closed form as the header states it, step by step.
Similarity closedForm(const std::vector<Vector3>& x, const std::vector<Vector3>& y,
                      bool with_scale) {
  const double n = static_cast<double>(x.size());
  Vector3 mean_x = Vector3::Zero(), mean_y = Vector3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    mean_x += x[i];
    mean_y += y[i];
  }
  mean_x /= n;
  mean_y /= n;
  double sigma2 = 0.0;
  Matrix3 covariance = Matrix3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    sigma2 += (x[i] - mean_x).squaredNorm() / n;
    covariance += (y[i] - mean_y) * (x[i] - mean_x).transpose() / n;
  }
  const Eigen::JacobiSVD<Matrix3> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3 S = Matrix3::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  const Matrix3 R = svd.matrixU() * S * svd.matrixV().transpose();
  const double c = with_scale ? (svd.singularValues().asDiagonal() * S).trace() / sigma2 : 1.0;
  return {SE3(SO3::fromMatrix(R), mean_y - c * R * mean_x), c};
}

std::vector<Vector3> randomPoints(std::mt19937& rng, int n, double spread_m) {
  std::normal_distribution<double> normal(0.0, spread_m);
  std::vector<Vector3> points;
  for (int i = 0; i < n; ++i) points.emplace_back(normal(rng), normal(rng), normal(rng));
  return points;
}

TEST(Umeyama, RecoversAKnownSimilarityAndRigidTransform) {
  const SE3 T(SO3::fromAxisAngle({1.0, -2.0, 0.5}, 0.7), Vector3(3.0, -4.0, 12.5));
  const double scale = 1.7;
  std::mt19937 rng(4);
  const std::vector<Vector3> source = randomPoints(rng, 12, 5.0);
  std::vector<Vector3> target, target_rigid;
  for (const Vector3& p : source) {
    target.push_back(scale * (T.rotation() * p) + T.translation());
    target_rigid.push_back(T * p);
  }
  const Similarity sim3 = umeyama(source, target, true);
  EXPECT_NEAR(sim3.scale, scale, 1e-12);
  EXPECT_TRUE(sim3.T_target_source.rotation().matrix().isApprox(T.rotation().matrix(), 1e-12));
  EXPECT_TRUE(sim3.T_target_source.translation().isApprox(T.translation(), 1e-12));
  const Similarity se3 = umeyama(source, target_rigid, false);
  EXPECT_EQ(se3.scale, 1.0);
  EXPECT_TRUE(se3.T_target_source.rotation().matrix().isApprox(T.rotation().matrix(), 1e-12));
  EXPECT_TRUE(se3.T_target_source.translation().isApprox(T.translation(), 1e-12));
}

TEST(Umeyama, AgreesWithTheClosedFormOnNoisyPoints) {
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int trial = 0; trial < 50; ++trial) {
    // Far from the origin (a georeferenced trajectory's ENU offsets are hundreds of metres).
    const Vector3 offset(400.0 * trial, -250.0, 30.0);
    std::vector<Vector3> source = randomPoints(rng, 5 + trial, 20.0), target;
    const SO3 R = SO3::fromAxisAngle({0.2, 0.1 * trial, 1.0}, 0.1 * trial);
    for (Vector3& p : source) {
      p += offset;
      target.push_back(1.01 * (R * p) + Vector3(noise(rng), noise(rng), noise(rng)) + offset);
    }
    for (const bool with_scale : {false, true}) {
      const Similarity a = umeyama(source, target, with_scale);
      const Similarity b = closedForm(source, target, with_scale);
      EXPECT_LT((a.T_target_source.rotation().matrix() - b.T_target_source.rotation().matrix())
                    .cwiseAbs()
                    .maxCoeff(),
                1e-12)
          << trial;
      EXPECT_LT((a.T_target_source.translation() - b.T_target_source.translation()).norm(),
                1e-12 * (1.0 + offset.norm()))
          << trial;
      EXPECT_NEAR(a.scale, b.scale, 1e-12) << trial;
    }
  }
}

TEST(Umeyama, GivesARotationWhereAReflectionWouldFitBetter) {
  std::mt19937 rng(2);
  const std::vector<Vector3> source = randomPoints(rng, 10, 3.0);
  std::vector<Vector3> mirrored;
  for (const Vector3& p : source) mirrored.emplace_back(p.x(), p.y(), -p.z());
  const Similarity a = umeyama(source, mirrored, false);
  EXPECT_NEAR(a.T_target_source.rotation().matrix().determinant(), 1.0, 1e-12);
}

TEST(Umeyama, RankCountsTheDirectionsThePointsSpan) {
  const std::vector<Vector3> line{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  const std::vector<Vector3> plane{{0, 0, 0}, {4, 0, 0}, {0, 3, 0}, {2, 5, 0}};
  const std::vector<Vector3> solid{{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 3}};
  const std::vector<Vector3> point{{1, 2, 3}, {1, 2, 3}};
  EXPECT_EQ(crossCovarianceRank(line, line), 1);
  EXPECT_EQ(crossCovarianceRank(plane, plane), 2);
  EXPECT_EQ(crossCovarianceRank(solid, solid), 3);
  EXPECT_EQ(crossCovarianceRank(point, point), 0);
  EXPECT_EQ(crossCovarianceRank({}, {}), 0);
}

}  // namespace
}  // namespace taiga::lie
