// NDT stem cells (ndt.hpp, "Stem cells"; docs/registration.md, "Bias"): a Gaussian of the arc of
// a stem that the map's sensor saw sits on that sensor's side; a scan from elsewhere sees another
// arc and is pulled toward the map's viewpoint. The circle fitted to the cell's horizontal
// moments is the same from every side.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration {
namespace {

TEST(VoxelStatistics, CircleMomentsAreTheSectionsCentralMoments) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.02, 0.48);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i) points.emplace_back(10.0 + u(rng), -20.0 + u(rng), 1.0 + u(rng));
  VoxelStatistics stats(0.5, true);
  stats.add(points);
  const std::vector<CellMoments> cells = stats.moments();
  ASSERT_EQ(cells.size(), 1u);
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p.head<2>() / 200.0;
  double xw = 0, yw = 0, ww = 0;
  for (const auto& p : points) {
    const Eigen::Vector2d d = p.head<2>() - mean;
    const double w = d.squaredNorm();
    xw += d.x() * w / 200.0;
    yw += d.y() * w / 200.0;
    ww += w * w / 200.0;
  }
  // 10 um quanta: within 1e-4 of the moments (the means of 200 points).
  EXPECT_NEAR(cells[0].xw, xw, 1e-7);
  EXPECT_NEAR(cells[0].yw, yw, 1e-7);
  EXPECT_NEAR(cells[0].ww, ww, 2e-8);
  EXPECT_GT(std::abs(xw) + std::abs(yw), 1e-5);  // not trivially zero
  // Removing the points empties the statistics exactly.
  stats.remove(points);
  EXPECT_EQ(stats.numCells(), 0u);
  EXPECT_TRUE(stats == VoxelStatistics(0.5, true));
  // Statistics without them cannot make stem cells.
  NdtConfig config;
  config.stem_cells = true;
  EXPECT_THROW(NdtTarget(VoxelStatistics(0.5), config), std::logic_error);
}

/// Points on the arc of a circle (centre c, radius r) facing `from`, half-angle `half_rad`, at
/// heights z0..z0+0.45 m, with range-like noise.
std::vector<Eigen::Vector3d> arc(const Eigen::Vector2d& c, double r, const Eigen::Vector2d& from,
                                 double half_rad, double z0, double noise_m, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, noise_m);
  const Eigen::Vector2d to = (from - c).normalized();
  const double facing = std::atan2(to.y(), to.x());
  std::vector<Eigen::Vector3d> points;
  for (double z = z0 + 0.02; z < z0 + 0.48; z += 0.05)
    for (double a = -half_rad; a <= half_rad; a += 0.05) {
      const Eigen::Vector2d p =
          c + (r + normal(rng)) * Eigen::Vector2d(std::cos(facing + a), std::sin(facing + a));
      points.emplace_back(p.x(), p.y(), z);
    }
  return points;
}

TEST(NdtStemCells, TheCircleOfAStemsArcIsFitted) {
  std::mt19937 rng(5);
  NdtConfig config;
  config.resolution_m = 0.5;
  config.stem_cells = true;
  // A 12 cm stem in one cell, seen as a 140 deg arc with 5 mm noise.
  const Eigen::Vector2d centre(3.25, 1.25);
  const auto stem = arc(centre, 0.12, {0.0, 0.0}, 1.22, 0.5, 0.005, rng);
  const NdtTarget target = NdtTarget::fromPoints(stem, 0.5, config);
  ASSERT_EQ(target.cells().size(), 1u);
  const NdtCell& cell = target.cells()[0];
  ASSERT_TRUE(cell.stem);
  EXPECT_NEAR((cell.stem_centre - centre).norm(), 0.0, 0.005);
  EXPECT_NEAR(cell.stem_radius_m, 0.12, 0.005);
  // Without the option the cell is a Gaussian only, and so are coarser passes' cells.
  EXPECT_FALSE(NdtTarget::fromPoints(stem, 0.5).cells()[0].stem);
  EXPECT_TRUE(config.cellsAt(0.5).stem_cells);
  EXPECT_FALSE(config.cellsAt(1.0).stem_cells);
}

// A stem seen from one side with range noise along the beams: fitted to the noisy points, the
// circle sits toward the viewer and comes out too small (errors in variables); with the points'
// beams the noise's share is taken out of the moments.
TEST(NdtStemCells, RangeNoiseAlongTheBeamsIsTakenOutOfTheCircle) {
  const Eigen::Vector2d centre(10.25, 0.25);
  const Eigen::Vector3d viewer(0.0, 0.25, 0.0);
  const double radius_m = 0.1, sigma_m = 0.01;
  const BeamNoise beams{viewer, sigma_m, 0.0};
  double toward_without_m = 0.0, toward_with_m = 0.0, radius_without_m = 0.0, radius_with_m = 0.0;
  constexpr int kRuns = 40;
  for (int run = 0; run < kRuns; ++run) {
    std::mt19937 rng(100 + run);
    std::normal_distribution<double> noise(0.0, sigma_m);
    // 120 deg of the near side, 400 points in the cell's height, noise along each beam.
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 400; ++i) {
      const double a = std::numbers::pi + (i % 40 - 19.5) / 39.0 * (2.0 * std::numbers::pi / 3.0);
      const Eigen::Vector3d on(centre.x() + radius_m * std::cos(a),
                               centre.y() + radius_m * std::sin(a), 0.01 + 0.012 * (i / 40));
      points.push_back(on + noise(rng) * (on - viewer).normalized());
    }
    for (const bool with_beams : {false, true}) {
      VoxelStatistics statistics(0.5, true);
      if (with_beams)
        statistics.add(points, beams);
      else
        statistics.add(points);
      NdtCell cell;
      ASSERT_TRUE(fitStemSection(statistics.moments().at(0), 0.5, 1e-6, cell))
          << run << " " << with_beams << " gate "
          << static_cast<int>(stemGateOf(statistics.moments().at(0), 0.5));
      // Toward the viewer is -x.
      (with_beams ? toward_with_m : toward_without_m) +=
          (centre.x() - cell.stem_centre.x()) / kRuns;
      (with_beams ? radius_with_m : radius_without_m) += (cell.stem_radius_m - radius_m) / kRuns;
    }
  }
  std::printf("centre toward the viewer %.2f / %.2f mm, radius %+.2f / %+.2f mm\n",
              1e3 * toward_without_m, 1e3 * toward_with_m, 1e3 * radius_without_m,
              1e3 * radius_with_m);
  EXPECT_GT(toward_without_m, 0.004);  // 9.5 mm in a Monte Carlo of this case
  EXPECT_LT(radius_without_m, -0.003);
  EXPECT_NEAR(toward_with_m, 0.0, 0.0015);
  EXPECT_NEAR(radius_with_m, 0.0, 0.0015);
}

TEST(NdtStemCells, WallsBlobsAndShortArcsAreNotStems) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(0.01, 0.49);
  NdtConfig config;
  config.resolution_m = 0.5;
  config.stem_cells = true;
  std::vector<Eigen::Vector3d> wall, blob;
  for (int i = 0; i < 100; ++i) wall.emplace_back(0.25, u(rng), u(rng));
  for (int i = 0; i < 100; ++i) blob.emplace_back(u(rng), u(rng), u(rng));
  for (const auto* points : {&wall, &blob}) {
    const NdtTarget target = NdtTarget::fromPoints(*points, 0.5, config);
    ASSERT_EQ(target.cells().size(), 1u);
    EXPECT_FALSE(target.cells()[0].stem);
  }
  // 34 deg of a 20 cm stem: the circle is not determined.
  const auto short_arc = arc({0.35, 0.25}, 0.2, {-5.0, 0.25}, 0.3, 0.0, 0.003, rng);
  const NdtTarget target = NdtTarget::fromPoints(short_arc, 0.5, config);
  ASSERT_EQ(target.cells().size(), 1u);
  EXPECT_FALSE(target.cells()[0].stem);

  // Which gate each fails (stemGateOf, a diagnosis); a 140 deg arc passes, 9 points do not.
  const auto gateOf = [](const std::vector<Eigen::Vector3d>& points) {
    VoxelStatistics statistics(0.5, true);
    statistics.add(points);
    return stemGateOf(statistics.moments().at(0), 0.5);
  };
  EXPECT_EQ(gateOf(wall), StemGate::kNoCircle);  // a straight section
  EXPECT_EQ(gateOf(blob), StemGate::kResidual);
  EXPECT_EQ(gateOf(short_arc), StemGate::kShortArc);
  const auto stem = arc({3.25, 1.25}, 0.12, {0.0, 0.0}, 1.22, 0.5, 0.005, rng);
  EXPECT_EQ(gateOf(stem), StemGate::kStem);
  EXPECT_EQ(gateOf({stem.begin(), stem.begin() + 9}), StemGate::kFewPoints);
}

TEST(NdtStemCells, ABlocksCircleIsTheCircleOfItsPooledPoints) {
  // A stem at the middle of a 1 m cell, all within one 0.5 m layer: the four 0.5 m cells around
  // it, pooled by their moments, must give the circle the 1 m cell's own moments give.
  std::mt19937 rng(8);
  const Eigen::Vector2d centre(20.5, -7.5);
  const auto stem = arc(centre, 0.15, {15.0, -9.0}, 2.2, 0.0, 0.004, rng);  // 250 deg
  VoxelStatistics fine(0.5, true), coarse(1.0, true);
  fine.add(stem);
  coarse.add(stem);
  const std::vector<CellMoments> quarters = fine.moments();
  const std::vector<CellMoments> whole = coarse.moments();
  ASSERT_EQ(quarters.size(), 4u);
  ASSERT_EQ(whole.size(), 1u);
  const CellMoments* block[] = {&quarters[0], &quarters[1], &quarters[2], &quarters[3]};
  NdtCell pooled, direct;
  pooled.covariance = direct.covariance = whole[0].covariance;
  ASSERT_TRUE(fitStemSection(whole[0], 1.0, 1e-6, direct));
  for (const CellMoments& own : quarters) {
    ASSERT_TRUE(fitStemSectionAcross(own, block, 1.0, 1e-6, pooled));
    EXPECT_NEAR((pooled.stem_centre - direct.stem_centre).norm(), 0.0, 1e-6);
    EXPECT_NEAR(pooled.stem_radius_m, direct.stem_radius_m, 1e-6);
    EXPECT_NEAR(pooled.inverse_radial_variance / direct.inverse_radial_variance, 1.0, 1e-3);
  }
  EXPECT_NEAR((direct.stem_centre - centre).norm(), 0.0, 0.004);
  // A cell whose points are off the block's circle (a twig across the block) does not take it.
  std::vector<Eigen::Vector3d> off;
  for (int i = 0; i < 40; ++i) off.emplace_back(20.05 + 0.01 * i, -7.95, 0.1 + 0.005 * i);
  VoxelStatistics elsewhere(0.5, true);
  elsewhere.add(off);
  EXPECT_FALSE(fitStemSectionAcross(elsewhere.moments()[0], block, 1.0, 1e-6, pooled));
}

TEST(NdtStemCells, AStemOnACellCornerBecomesStemCells) {
  // A 12 cm stem whose axis is the corner of four 0.5 m cells, seen from the -x side as a
  // 140 deg arc: each of the two cells holds 70 deg, whose own circle fails the gates; the
  // 2 x 2 block's passes.
  std::mt19937 rng(9);
  const Eigen::Vector2d centre(3.0, 1.0);
  std::vector<Eigen::Vector3d> stem;
  for (double z0 = 0.0; z0 < 1.5; z0 += 0.5)
    for (const auto& p : arc(centre, 0.12, {-1.0, 1.0}, 1.2, z0, 0.004, rng)) stem.push_back(p);
  NdtConfig config;
  config.resolution_m = 0.5;
  config.stem_cells = true;
  const auto stemCells = [&](bool across) {
    config.stem_cells_across_borders = across;
    const NdtTarget target = NdtTarget::fromPoints(stem, 0.5, config);
    int n = 0;
    for (const NdtCell& cell : target.cells()) {
      if (!cell.stem) continue;
      ++n;
      EXPECT_NEAR((cell.stem_centre - centre).norm(), 0.0, 0.01);
      EXPECT_NEAR(cell.stem_radius_m, 0.12, 0.01);
    }
    return std::pair(n, static_cast<int>(target.cells().size()));
  };
  const auto [within, cells] = stemCells(false);
  const auto [across, same_cells] = stemCells(true);
  EXPECT_EQ(cells, same_cells);
  EXPECT_EQ(cells, 6);
  EXPECT_EQ(within, 0);
  EXPECT_EQ(across, cells);
}

/// A scan 4 m ahead of the map's viewpoint, registered from its true pose: the map saw each stem
/// from (0, 0), the scan from (4, 0); flat ground below. The error along the walk (m).
double pullAlongWalk_m(bool stem_cells) {
  std::mt19937 rng(7);
  const Eigen::Vector2d stems[] = {{2.25, 3.25}, {1.75, -3.25}, {4.25, 4.25},
                                   {3.25, -3.75}, {6.25, 2.75}, {5.75, -2.25}};
  std::vector<Eigen::Vector3d> map, scan_in_world;
  for (const Eigen::Vector2d& c : stems)
    for (double z0 = -1.0; z0 < 1.5; z0 += 0.5) {
      for (const auto& p : arc(c, 0.12, {0.0, 0.0}, 1.3, z0, 0.005, rng)) map.push_back(p);
      for (const auto& p : arc(c, 0.12, {4.0, 0.0}, 1.3, z0, 0.005, rng))
        scan_in_world.push_back(p);
    }
  std::uniform_real_distribution<double> u(-8.0, 8.0);
  for (int i = 0; i < 4000; ++i) {
    map.emplace_back(u(rng), u(rng), -1.2);
    scan_in_world.emplace_back(u(rng), u(rng), -1.2);
  }
  const lie::SE3 T_world_scan(lie::SO3(), Eigen::Vector3d(4.0, 0.0, 0.0));
  std::vector<Eigen::Vector3d> scan;
  for (const auto& p : scan_in_world) scan.push_back(T_world_scan.inverse() * p);
  NdtConfig config;
  config.resolution_m = 0.5;
  config.stem_cells = stem_cells;
  const RegistrationResult result = alignNdt(scan, map, T_world_scan, config);
  EXPECT_TRUE(result.converged);
  return result.T_target_source.translation().x() - 4.0;
}

TEST(NdtStemCells, AScanIsNotMovedByTheArcsItsViewpointSaw) {
  const double gaussian_m = pullAlongWalk_m(false);
  const double circles_m = pullAlongWalk_m(true);
  std::printf("error along the walk: Gaussian cells %+.4f m, stem cells %+.4f m\n", gaussian_m,
              circles_m);
  // The arcs' Gaussians sit on the sides each sensor saw and move the scan (+1.8 cm written).
  EXPECT_GT(std::abs(gaussian_m), 0.005);
  EXPECT_LT(std::abs(circles_m), 0.2 * std::abs(gaussian_m));
  EXPECT_LT(std::abs(circles_m), 0.002);
}

}  // namespace
}  // namespace taiga::registration
