// NDT line cells (docs/registration.md, "Line cells"): a sparse lidar's ground rings keep their
// range from the sensor as it moves, so a scan scored against the previous scan's rings is pulled
// back towards that scan's viewpoint; cells whose points lie along a line are not used.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/registration/ndt.hpp"

namespace taiga::registration {
namespace {

constexpr double kSensorHeight_m = 1.5;

/// A 16-beam scan taken at (x_m, 0, 0) in the world, as points in the sensor frame: the rings
/// of the beams below the horizon on flat ground, 1024 columns, and the visible arcs of stems.
std::vector<Eigen::Vector3d> sparseScan(double x_m) {
  std::vector<Eigen::Vector3d> points;
  const double column_rad = 2.0 * std::numbers::pi / 1024.0;
  for (double elevation_deg = -15.0; elevation_deg < -6.0; elevation_deg += 2.0) {
    const double range_m = kSensorHeight_m / std::tan(-elevation_deg * std::numbers::pi / 180.0);
    for (int c = 0; c < 1024; ++c)
      points.emplace_back(range_m * std::cos(c * column_rad), range_m * std::sin(c * column_rad),
                          -kSensorHeight_m);
  }
  // Stems of 0.15 m radius around the walk, each seen as the arc facing the sensor, every 0.3 m
  // of height (a 2 deg beam spacing at 8 m).
  const Eigen::Vector2d stems[] = {{4, 3}, {-3, 5}, {6, -4}, {-5, -3}, {1, 7}, {8, 1}, {-7, 2}};
  for (const Eigen::Vector2d& stem : stems) {
    const Eigen::Vector2d to_sensor = (Eigen::Vector2d(x_m, 0) - stem).normalized();
    const double facing = std::atan2(to_sensor.y(), to_sensor.x());
    for (double z = -kSensorHeight_m; z < 3.0; z += 0.3)
      for (double a = -1.2; a <= 1.2; a += 0.1) {
        const Eigen::Vector2d p =
            stem + 0.15 * Eigen::Vector2d(std::cos(facing + a), std::sin(facing + a));
        points.emplace_back(p.x() - x_m, p.y(), z);
      }
  }
  return points;
}

/// How far NDT (1 m cells, each point against its own cell) leaves the scan taken 0.1 m ahead
/// of the map's (a scan at 1 m/s), started from the true pose, along the walk (m; negative:
/// pulled back).
double pullAlongWalk_m(double line_cell_ratio) {
  NdtConfig config;
  config.resolution_m = 1.0;
  config.search = NeighbourSearch::kDirect1;
  config.line_cell_ratio = line_cell_ratio;
  const std::vector<Eigen::Vector3d> map = sparseScan(0.0);
  const std::vector<Eigen::Vector3d> scan = sparseScan(0.1);
  const lie::SE3 truth(lie::SO3(), Eigen::Vector3d(0.1, 0, 0));
  const RegistrationResult result = alignNdt(scan, map, truth, config);
  EXPECT_TRUE(result.converged);
  return result.T_target_source.translation().x() - 0.1;
}

TEST(NdtLineCells, ARingOfTheMapDoesNotPullTheScanBack) {
  // With the rings scored, the scan settles most of the way back to the map's viewpoint (8.9 cm
  // of the 10 when written); without them the stems place it.
  EXPECT_LT(pullAlongWalk_m(0.0), -0.05);
  EXPECT_NEAR(pullAlongWalk_m(NdtConfig{}.line_cell_ratio), 0.0, 0.005);
}

TEST(NdtLineCells, LinesAreDroppedPlanesKept) {
  // A cell with a line of points and one with a patch of plane.
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 50; ++i) points.emplace_back(0.1 + 0.016 * i, 0.5, 0.5);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) points.emplace_back(2.1 + 0.08 * i, 0.1 + 0.08 * j, 0.5);
  NdtConfig keep_lines;
  keep_lines.line_cell_ratio = 0.0;
  EXPECT_EQ(NdtTarget::fromPoints(points, 1.0).cells().size(), 1u);
  EXPECT_EQ(NdtTarget::fromPoints(points, 1.0, keep_lines).cells().size(), 2u);
  NdtConfig bad;
  bad.line_cell_ratio = 1.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace taiga::registration
