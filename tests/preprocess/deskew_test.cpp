#include "taiga/preprocess/deskew.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "../imu/imu_test_motion.hpp"
#include "taiga/imu/propagation.hpp"

namespace taiga::preprocess {
namespace {

using imu::test::kGravityWorld;
using imu::test::WavyMotion;

const lie::SE3 kT_body_lidar(lie::SO3::fromRollPitchYaw(0.02, -0.03, 3.14159),
                             Eigen::Vector3d(0.05, -0.1, 0.2));
constexpr double kScanStart = 2.0, kScanPeriod = 0.1;
constexpr int kColumns = 1024;

lie::SE3 truePose(double t) {
  const imu::NavState s = WavyMotion::state(t);
  return lie::SE3(s.R_world_body, s.p_world);
}

/// The true poses at 400 Hz over the sweep and 10 ms either side.
Trajectory trueSweep() {
  Trajectory trajectory;
  for (double t = kScanStart - 0.01; t <= kScanStart + kScanPeriod + 0.01; t += 0.0025)
    trajectory.append(t, truePose(t));
  return trajectory;
}

/// Static world points seen by the moving lidar, each at a random column's firing time.
struct SimulatedScan {
  std::vector<Eigen::Vector3d> points_in_world;
  PointCloud cloud_in_lidar;
};

SimulatedScan simulateScan(int points) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), range(3.0, 30.0);
  std::uniform_int_distribution<int> column(0, kColumns - 1);
  SimulatedScan scan;
  const Eigen::Vector3d center = WavyMotion::position(kScanStart);
  for (int i = 0; i < points; ++i) {
    const Eigen::Vector3d direction =
        Eigen::Vector3d(unit(rng), unit(rng), 0.3 * unit(rng)).normalized();
    const Eigen::Vector3d p_world = center + range(rng) * direction;
    const double t = kScanStart + column(rng) * kScanPeriod / kColumns;
    scan.points_in_world.push_back(p_world);
    scan.cloud_in_lidar.positions.push_back((truePose(t) * kT_body_lidar).inverse() * p_world);
    scan.cloud_in_lidar.times_s.push_back(t);
  }
  return scan;
}

/// Largest distance between the deskewed points, placed in the world with the true pose at
/// t_ref, and the world points they came from.
double worldError(const SimulatedScan& scan, const DeskewedScan& deskewed) {
  const lie::SE3 T_world_bodyref = truePose(deskewed.t_ref_s);
  double worst = 0.0;
  for (std::size_t i = 0; i < scan.points_in_world.size(); ++i) {
    worst = std::max(
        worst,
        (T_world_bodyref * deskewed.cloud_in_body.positions[i] - scan.points_in_world[i]).norm());
  }
  return worst;
}

TEST(Deskew, PutsEveryPointWhereItWasWithTheTrueTrajectory) {
  const SimulatedScan scan = simulateScan(5000);
  const Trajectory trajectory = trueSweep();
  const double t_ref = kScanStart + kScanPeriod;
  const DeskewedScan deskewed = deskew(scan.cloud_in_lidar, kT_body_lidar, trajectory, t_ref);
  EXPECT_EQ(deskewed.clamped_points, 0u);
  EXPECT_LT(worldError(scan, deskewed), 2e-3);  // interpolation between 400 Hz poses, at up to 30 m
  EXPECT_TRUE(deskewed.cloud_in_body.isConsistent());
}

TEST(Deskew, WorksWithPosesFromImuPropagation) {
  const SimulatedScan scan = simulateScan(5000);
  std::vector<ImuSample> samples;
  for (double t = kScanStart - 0.05; t < kScanStart + 0.2; t += 0.0025) {
    samples.push_back({t, WavyMotion::accel(t + 0.00125), WavyMotion::gyro(t + 0.00125), {}});
  }
  const auto states = imu::propagateThrough(WavyMotion::state(kScanStart), kScanStart,
                                            kScanStart + kScanPeriod, samples, {}, kGravityWorld);
  const DeskewedScan deskewed = deskew(scan.cloud_in_lidar, kT_body_lidar,
                                       imu::toTrajectory(states), kScanStart + kScanPeriod);
  EXPECT_LT(worldError(scan, deskewed), 5e-3);
}

TEST(Deskew, WithoutMotionCompensationTheScanIsSkewed) {
  // The same scan with a constant pose: the sweep's motion smears points by centimetres, which is
  // what deskewing removes (the test above would fail by this much if deskew did nothing).
  const SimulatedScan scan = simulateScan(5000);
  Trajectory frozen;
  frozen.append(kScanStart + kScanPeriod, truePose(kScanStart + kScanPeriod));
  const DeskewedScan deskewed =
      deskew(scan.cloud_in_lidar, kT_body_lidar, frozen, kScanStart + kScanPeriod);
  EXPECT_GT(worldError(scan, deskewed), 0.05);
  EXPECT_EQ(deskewed.clamped_points,
            scan.cloud_in_lidar.size() - std::count(scan.cloud_in_lidar.times_s.begin(),
                                                    scan.cloud_in_lidar.times_s.end(),
                                                    kScanStart + kScanPeriod));
}

TEST(Deskew, AColumnChannelChangesNothingEvenWhenItDisagreesWithTheTimes) {
  // deskew guesses a point's time from its column's previous one, checked bit for bit: a column
  // channel that matches the times, or one that does not, gives the same points as none.
  const SimulatedScan scan = simulateScan(5000);
  const Trajectory trajectory = trueSweep();
  const double t_ref = kScanStart + kScanPeriod;
  const PointCloud plain =
      deskew(scan.cloud_in_lidar, kT_body_lidar, trajectory, t_ref).cloud_in_body;
  PointCloud matching = scan.cloud_in_lidar, unrelated = scan.cloud_in_lidar;
  std::mt19937_64 rng(3);
  for (double t : scan.cloud_in_lidar.times_s) {
    matching.columns.push_back(
        static_cast<std::uint16_t>(std::lround((t - kScanStart) / kScanPeriod * kColumns)));
    unrelated.columns.push_back(static_cast<std::uint16_t>(rng() % 7));
  }
  for (const PointCloud* with_columns : {&matching, &unrelated}) {
    const PointCloud deskewed =
        deskew(*with_columns, kT_body_lidar, trajectory, t_ref).cloud_in_body;
    EXPECT_EQ(deskewed.positions, plain.positions);
  }
}

TEST(Deskew, RejectsACloudWithoutTimes) {
  PointCloud cloud;
  cloud.positions = {{1, 2, 3}};
  Trajectory trajectory;
  trajectory.append(0.0, lie::SE3());
  EXPECT_THROW(deskew(cloud, kT_body_lidar, trajectory, 0.0), std::invalid_argument);
  EXPECT_THROW(deskew(PointCloud{}, kT_body_lidar, Trajectory{}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace taiga::preprocess
