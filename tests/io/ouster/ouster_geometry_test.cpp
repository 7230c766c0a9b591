// Range to XYZ against the formula of the Ouster firmware user manual, written out independently.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "ouster_test_support.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/io/ouster/beam_geometry.hpp"

namespace taiga::io::ouster {
namespace {

constexpr double kPi = std::numbers::pi;

SensorInfo simpleSensor(int columns, std::vector<double> altitude_deg,
                        std::vector<double> azimuth_deg) {
  SensorInfo info;
  info.columns_per_frame = columns;
  info.pixels_per_column = static_cast<int>(altitude_deg.size());
  info.beam_altitude_angles_deg = std::move(altitude_deg);
  info.beam_azimuth_angles_deg = std::move(azimuth_deg);
  return info;  // beam origin at the lidar origin, lidar frame = sensor frame
}

TEST(OusterGeometry, ColumnZeroLooksAlongLidarXAndColumnsTurnClockwise) {
  const BeamGeometry geometry(simpleSensor(1024, {0.0, 45.0}, {0.0, 0.0}));
  EXPECT_TRUE(geometry.pointInSensor(0, 0, 10000).isApprox(Eigen::Vector3d(10, 0, 0)));
  // A quarter turn later the beam points along -y: the encoder angle decreases with the id.
  EXPECT_TRUE(geometry.pointInSensor(0, 256, 10000).isApprox(Eigen::Vector3d(0, -10, 0), 1e-12));
  EXPECT_TRUE(geometry.pointInSensor(0, 512, 2000).isApprox(Eigen::Vector3d(-2, 0, 0), 1e-12));
  const Eigen::Vector3d up = geometry.pointInSensor(1, 0, 2000);
  EXPECT_NEAR(up.x(), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(up.z(), std::sqrt(2.0), 1e-12);
}

TEST(OusterGeometry, MatchesTheUserManualFormulaWithBeamOffsetsAndSensorTransform) {
  const SensorInfo info = readSensorInfo(test::ousterData("OS-0-128-U1_v2.3.0_1024x10.json"));
  const BeamGeometry geometry(info);
  const double n = info.lidar_origin_to_beam_origin_mm;
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int row = static_cast<int>(rng() % 128);
    const int id = static_cast<int>(rng() % 1024);
    const double r = 500.0 + static_cast<double>(rng() % 100000);
    // "Lidar Range to XYZ": theta_encoder = 2 pi (1 - id / W), theta_azimuth = -2 pi az / 360.
    const double theta_e = 2 * kPi * (1.0 - id / 1024.0);
    const double theta_a =
        -2 * kPi * info.beam_azimuth_angles_deg[static_cast<std::size_t>(row)] / 360;
    const double phi = 2 * kPi * info.beam_altitude_angles_deg[static_cast<std::size_t>(row)] / 360;
    const Eigen::Vector3d lidar_mm(
        (r - n) * std::cos(theta_e + theta_a) * std::cos(phi) + n * std::cos(theta_e),
        (r - n) * std::sin(theta_e + theta_a) * std::cos(phi) + n * std::sin(theta_e),
        (r - n) * std::sin(phi));
    // lidar_to_sensor_transform: 180 deg about z, 36.18 mm up.
    const Eigen::Vector3d expected_m(-lidar_mm.x() / 1000, -lidar_mm.y() / 1000,
                                     lidar_mm.z() / 1000 + 0.03618);
    const Eigen::Vector3d actual = geometry.pointInSensor(row, id, static_cast<std::uint32_t>(r));
    EXPECT_LT((actual - expected_m).norm(), 1e-9) << row << " " << id;
    EXPECT_NEAR((actual - Eigen::Vector3d(0, 0, 0.03618)).norm(), (r - n) / 1000, n / 1000 + 1e-9);
  }
}

TEST(OusterGeometry, BeamToLidarTransformAddsTheBeamOriginHeight) {
  SensorInfo info = simpleSensor(512, {10.0}, {0.0});
  info.T_lidar_beam = lie::SE3(lie::SO3(), Eigen::Vector3d(0.03, 0.0, 0.004));
  const BeamGeometry geometry(info);
  const double n = std::hypot(30.0, 4.0);
  const double r = 5000.0;
  const double phi = 10.0 * kRadPerDeg;
  const Eigen::Vector3d p = geometry.pointInSensor(0, 0, static_cast<std::uint32_t>(r));
  EXPECT_NEAR(p.x(), ((r - n) * std::cos(phi) + 30.0) / 1000, 1e-12);
  EXPECT_NEAR(p.y(), 0.0, 1e-12);
  EXPECT_NEAR(p.z(), ((r - n) * std::sin(phi) + 4.0) / 1000, 1e-12);
}

}  // namespace
}  // namespace taiga::io::ouster
