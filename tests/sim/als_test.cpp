// The simulated airborne survey (sim/als.hpp): the density asked for, ground returns on the
// terrain and first returns on the canopy, last returns below the first, the same cloud whatever
// the thread count, and the LAS file in the grid with return numbers and classes.
#include "taiga/sim/als.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <fstream>
#include <iterator>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/sim/georef_truth.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

const Simulation& simulation() {
  static const Simulation sim(scenarioByName("mixed"), 10.0, 3);
  return sim;
}

/// The centre 30 x 30 m of the plot at 5 pulses per m^2.
const AlsReturns& survey() {
  static const AlsReturns als =
      simulateAls(simulation().scene(), simulation().scene().layout().center_world, 15.0, {}, 3);
  return als;
}

TEST(Als, PulsesAtTheDensityAskedForWithFirstAndLastReturns) {
  const AlsReturns& als = survey();
  EXPECT_EQ(als.pulses, 4500u);  // 5 per m^2 over 900 m^2
  ASSERT_EQ(als.returns.size(), als.cloud.size());
  ASSERT_EQ(als.classifications.size(), als.cloud.size());
  std::size_t first = 0, two = 0;
  for (std::size_t i = 0; i < als.returns.size(); ++i) {
    const auto [number, of] = als.returns[i];
    ASSERT_TRUE((number == 1 && (of == 1 || of == 2)) || (number == 2 && of == 2));
    if (number == 1) ++first;
    if (number == 2) {
      ++two;
      ASSERT_EQ(als.returns[i - 1][0], 1);  // follows its pulse's first return
      const Eigen::Vector3d& a = als.cloud.positions[i - 1];
      const Eigen::Vector3d& b = als.cloud.positions[i];
      EXPECT_GT(a.z() - b.z(), 1.5);  // more than the separation, seen from almost straight above
    }
  }
  EXPECT_EQ(first, als.pulses);  // every pulse meets the ground at least
  // A forest: the canopy splits many pulses, and stops some before the ground.
  EXPECT_GT(two, als.pulses / 10);
  EXPECT_LT(two, als.pulses);
}

TEST(Als, GroundReturnsLieOnTheTerrainAndTheCanopyAboveIt) {
  const AlsReturns& als = survey();
  const Terrain& terrain = simulation().scene().terrain();
  std::size_t ground = 0, high = 0;
  for (std::size_t i = 0; i < als.cloud.size(); ++i) {
    const Eigen::Vector3d& p = als.cloud.positions[i];
    const double above_m = p.z() - terrain.height(p.x(), p.y());
    if (als.classifications[i] == 2) {
      ++ground;
      EXPECT_NEAR(above_m, 0.0, 0.25) << i;  // 3 cm range noise, 5 cm horizontal on slopes
    } else {
      EXPECT_EQ(als.classifications[i], 1);
      if (above_m > 8.0) ++high;
    }
  }
  EXPECT_GT(ground, als.pulses / 4);
  EXPECT_GT(high, als.pulses / 10);  // crowns
}

TEST(Als, TheSameCloudOnOneThreadAsOnMany) {
  AlsReturns one;
  tbb::task_arena(1).execute([&] {
    one =
        simulateAls(simulation().scene(), simulation().scene().layout().center_world, 15.0, {}, 3);
  });
  EXPECT_EQ(one.cloud.positions, survey().cloud.positions);
  EXPECT_EQ(one.returns, survey().returns);
  const AlsReturns other_seed =
      simulateAls(simulation().scene(), simulation().scene().layout().center_world, 15.0, {}, 4);
  EXPECT_NE(other_seed.cloud.positions, survey().cloud.positions);
}

TEST(Als, TheFileIsInTheGridWithReturnNumbersAndClasses) {
  test::TempDir dir;
  const auto path = dir.file("als.las");
  const AlsSummary summary = writeAls(simulation(), path, {.pulses_per_m2 = 1.0});
  EXPECT_GT(summary.points, summary.pulses);
  io::LasReader reader(path);
  ASSERT_EQ(reader.pointCount(), summary.points);
  PointCloud cloud;
  reader.read(0, reader.pointCount(), cloud);
  // ETRS-TM35FIN around the simulator's origin (61 N, 24.5 E): millions of metres north.
  const GeorefTruth truth = georefTruth(simulation().scenario().gnss);
  const Eigen::Vector2d center = simulation().scene().layout().center_world;
  const Eigen::Vector3d center_grid =
      (truth.T_epsg_world * Eigen::Vector4d(center.x(), center.y(), 0.0, 1.0)).head<3>();
  for (const Eigen::Vector3d& p : cloud.positions) {
    EXPECT_LT(std::abs(p.x() - center_grid.x()), simulation().scene().layout().half_size_m * 1.5);
    EXPECT_LT(std::abs(p.y() - center_grid.y()), simulation().scene().layout().half_size_m * 1.5);
  }
  EXPECT_GT(center_grid.y(), 6.7e6);

  // Point format 6: the return byte at 14, the class at 16 of each 30-byte record.
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::size_t seconds = 0, ground = 0;
  for (std::size_t i = 0; i < reader.pointCount(); ++i) {
    const std::size_t record = reader.header().point_data_offset + 30 * i;
    const auto returns = static_cast<std::uint8_t>(bytes[record + 14]);
    const int number = returns & 0x0F, of = returns >> 4;
    ASSERT_TRUE(number >= 1 && number <= of && of <= 2) << i;
    seconds += number == 2;
    ground += bytes[record + 16] == 2;
  }
  EXPECT_EQ(seconds, summary.last_returns);
  EXPECT_EQ(ground, summary.ground_points);
  EXPECT_NE(bytes.find("TM35FIN"), std::string::npos);  // the CRS in the header's WKT
}

TEST(Als, InvalidParametersAreNamed) {
  const auto message = [](const AlsParams& p) {
    try {
      simulateAls(simulation().scene(), Eigen::Vector2d::Zero(), 10.0, p, 1);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({.pulses_per_m2 = 0.0}).find("pulses_per_m2"), std::string::npos);
  EXPECT_NE(message({.half_swath_deg = 75.0}).find("half_swath_deg"), std::string::npos);
  EXPECT_NE(message({.rays_per_pulse = 0}).find("rays_per_pulse"), std::string::npos);
}

}  // namespace
}  // namespace taiga::sim
