#include "taiga/preprocess/voxel_filter.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

namespace taiga::preprocess {
namespace {

PointCloud cloudOf(std::vector<Eigen::Vector3d> points) {
  PointCloud cloud;
  for (std::size_t i = 0; i < points.size(); ++i) {
    cloud.positions.push_back(points[i]);
    cloud.times_s.push_back(static_cast<double>(i));
  }
  return cloud;
}

/// n points uniform in x, y within +-half_width_m and in z within +-z_scale * half_width_m.
std::vector<Eigen::Vector3d> randomSlab(std::mt19937_64& rng, int n, double half_width_m,
                                        double z_scale) {
  std::uniform_real_distribution<double> coordinate(-half_width_m, half_width_m);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i)
    points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng) * z_scale);
  return points;
}

TEST(VoxelFilter, OnePointPerVoxelAtTheCentroid) {
  // Two points in voxel (0,0,0), one in (-1,0,0) (negative coordinates floor down), one in (2,3,4).
  const PointCloud cloud =
      cloudOf({{0.1, 0.1, 0.1}, {0.3, 0.1, 0.2}, {-0.1, 0.2, 0.2}, {0.9, 1.3, 1.7}});
  const PointCloud filtered = voxelFilter(cloud, 0.4);
  ASSERT_EQ(filtered.size(), 3u);
  ASSERT_TRUE(filtered.isConsistent());
  std::vector<Eigen::Vector3d> got = filtered.positions;
  auto has = [&](const Eigen::Vector3d& p) {
    return std::any_of(got.begin(), got.end(),
                       [&](const Eigen::Vector3d& q) { return (p - q).norm() < 1e-12; });
  };
  EXPECT_TRUE(has({0.2, 0.1, 0.15}));
  EXPECT_TRUE(has({-0.1, 0.2, 0.2}));
  EXPECT_TRUE(has({0.9, 1.3, 1.7}));
}

TEST(VoxelFilter, SameOutputWhateverTheInputOrderAndDropsNonFinitePoints) {
  std::mt19937_64 rng(3);
  std::vector<Eigen::Vector3d> points = randomSlab(rng, 20000, 20.0, 0.1);
  points.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  PointCloud cloud = cloudOf(points);
  const PointCloud once = voxelFilter(cloud, 0.5);
  std::shuffle(points.begin(), points.end(), rng);
  const PointCloud shuffled = voxelFilter(cloudOf(points), 0.5);
  ASSERT_EQ(once.size(), shuffled.size());
  for (std::size_t i = 0; i < once.size(); ++i) {
    ASSERT_TRUE(once.positions[i].allFinite());
    // Centroids are sums in another order: equal up to rounding.
    EXPECT_LT((once.positions[i] - shuffled.positions[i]).norm(), 1e-12);
  }
  EXPECT_LT(once.size(), cloud.size());
}

TEST(VoxelFilter, TheSameBitsOnOneWorkerThreadAsOnMany) {
  // The voxels are split into partitions filtered in parallel; each voxel's points are still
  // summed in index order, so the thread count changes nothing (the odometry's outputs rely on
  // it: docs/architecture.md, "Threads").
  std::mt19937_64 rng(5);
  const PointCloud cloud = cloudOf(randomSlab(rng, 50000, 30.0, 0.2));
  const PointCloud many = voxelFilter(cloud, 0.4, VoxelRepresentative::centroid);
  const PointCloud measured_many = voxelFilter(cloud, 0.4, VoxelRepresentative::measured);
  PointCloud one, measured_one;
  {
    const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = voxelFilter(cloud, 0.4, VoxelRepresentative::centroid);
    measured_one = voxelFilter(cloud, 0.4, VoxelRepresentative::measured);
  }
  ASSERT_GT(many.size(), 10000u);
  EXPECT_EQ(one.positions, many.positions);  // exactly
  EXPECT_EQ(one.times_s, many.times_s);
  EXPECT_EQ(measured_one.positions, measured_many.positions);
  // In key order (x, then y, then z voxel index), as before the partitions.
  for (std::size_t i = 1; i < many.size(); ++i) {
    const Eigen::Vector3d a = (many.positions[i - 1] / 0.4).array().floor();
    const Eigen::Vector3d b = (many.positions[i] / 0.4).array().floor();
    ASSERT_TRUE(std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3)) << i;
  }
}

TEST(VoxelFilter, KeepsTheChannelsOfThePointNearestTheCentroid) {
  // The centroid of the three is (0.2, 0, 0): the middle point, time 7, is nearest.
  PointCloud cloud = cloudOf({{0.0, 0.0, 0.0}, {0.19, 0.0, 0.0}, {0.41, 0.0, 0.0}});
  cloud.times_s = {5.0, 7.0, 9.0};
  cloud.intensities = {1.0f, 2.0f, 3.0f};
  const PointCloud filtered = voxelFilter(cloud, 1.0);
  ASSERT_EQ(filtered.size(), 1u);
  EXPECT_DOUBLE_EQ(filtered.times_s[0], 7.0);
  EXPECT_FLOAT_EQ(filtered.intensities[0], 2.0f);
}

TEST(VoxelFilter, TheMeasuredRepresentativeLiesOnACurvedSurfaceWhereTheCentroidDoesNot) {
  // The half of a 10 cm radius stem facing a sensor on the -x side, in one 0.4 m voxel: the
  // centroid is 2r/pi = 6.4 cm from the axis toward the sensor, 3.6 cm inside the bark.
  const Eigen::Vector3d axis(0.2, 0.2, 0.2);
  std::vector<Eigen::Vector3d> arc;
  for (int i = 0; i <= 180; ++i) {
    const double phi = (90.0 + i) * M_PI / 180.0;
    arc.push_back(axis + 0.1 * Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0));
  }
  const PointCloud cloud = cloudOf(arc);
  const auto radius = [&](const PointCloud& filtered) {
    EXPECT_EQ(filtered.size(), 1u);
    return (filtered.positions[0] - axis).head<2>().norm();
  };
  EXPECT_NEAR(radius(voxelFilter(cloud, 0.4)), 0.2 / M_PI, 1e-3);
  const PointCloud measured = voxelFilter(cloud, 0.4, VoxelRepresentative::measured);
  EXPECT_NEAR(radius(measured), 0.1, 1e-12);
  EXPECT_EQ(measured.times_s[0], 90.0);  // the point facing the sensor, its own channels
}

TEST(VoxelFilter, TheBearingRepresentativeIsNotChosenForItsRangeNoise) {
  // The 10 cm stem's near half again, seen from a sensor 5 m away with 1 cm range noise. The
  // return nearest the centroid is the one whose noise carried it deepest toward the centroid:
  // inside the bark on average. The return nearest the centroid's bearing is chosen by its
  // direction alone, so its range error averages out.
  const Eigen::Vector3d axis(0.2, 0.2, 0.2), sensor(-4.8, 0.2, 0.2);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> range_noise(0.0, 0.01);
  double measured_sum = 0.0, bearing_sum = 0.0;
  constexpr int kTrials = 2000;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::vector<Eigen::Vector3d> arc;
    for (int i = 0; i <= 180; ++i) {
      const double phi = (90.0 + i) * M_PI / 180.0;
      const Eigen::Vector3d p = axis + 0.1 * Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0);
      arc.push_back(p + range_noise(rng) * (p - sensor).normalized());
    }
    const PointCloud cloud = cloudOf(arc);
    const auto radius = [&](VoxelRepresentative representative) {
      const PointCloud filtered = voxelFilter(cloud, 0.4, representative, sensor);
      EXPECT_EQ(filtered.size(), 1u);
      return (filtered.positions[0] - axis).head<2>().norm();
    };
    measured_sum += radius(VoxelRepresentative::measured);
    bearing_sum += radius(VoxelRepresentative::bearing);
  }
  const double measured_bias_m = measured_sum / kTrials - 0.1;
  const double bearing_bias_m = bearing_sum / kTrials - 0.1;
  std::printf("radius bias: measured %+.2f mm, bearing %+.2f mm\n", 1e3 * measured_bias_m,
              1e3 * bearing_bias_m);
  EXPECT_LT(measured_bias_m, -0.003);
  EXPECT_LT(std::abs(bearing_bias_m), 0.001);  // 4 standard errors of the mean
}

TEST(VoxelFilter, RepresentativesByName) {
  EXPECT_EQ(voxelRepresentative("centroid"), VoxelRepresentative::centroid);
  EXPECT_EQ(voxelRepresentative("measured"), VoxelRepresentative::measured);
  EXPECT_EQ(voxelRepresentative("bearing"), VoxelRepresentative::bearing);
  EXPECT_THROW(voxelRepresentative("median"), std::invalid_argument);
}

TEST(VoxelFilter, RejectsANonPositiveSizeAndAcceptsAnEmptyCloud) {
  EXPECT_THROW(voxelFilter(PointCloud{}, 0.0), std::invalid_argument);
  EXPECT_TRUE(voxelFilter(PointCloud{}, 0.4).empty());
}

}  // namespace
}  // namespace taiga::preprocess
