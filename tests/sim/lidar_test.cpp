// The simulated lidar: deterministic whatever the thread count, points on true surfaces when
// transformed by the true pose at their column's time, sensible returns per scan.
#include <gtest/gtest.h>

#include "taiga/core/errors.hpp"
#include <tbb/task_arena.h>

#include <algorithm>
#include <vector>

#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

/// A reduced head (32 x 512) keeps the tests fast; the geometry code is the same.
Scenario smallScenario(bool noise) {
  Scenario s = scenarioByName("mixed");
  s.lidar.beams = 32;
  s.lidar.columns = 512;
  s.lidar.noise = noise;
  if (!noise) s.lidar.sub_rays = 1;
  return s;
}

/// Distances from every point (in the world at its own time) to the nearest true surface.
std::vector<double> surfaceDistances(const Simulation& sim, const io::Scan& scan) {
  const lie::SE3 T_body_lidar = sim.lidar().T_body_lidar();
  std::vector<double> d;
  const PointCloud& cloud = scan.cloud_in_lidar;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const lie::SE3 T_world_body = sim.motion().at(cloud.times_s[i]).T_world_body;
    d.push_back(
        sim.scene().distanceToSurface(T_world_body * (T_body_lidar * cloud.positions[i]), 2.0));
  }
  std::sort(d.begin(), d.end());
  return d;
}

double quantile(const std::vector<double>& sorted, double q) {
  return sorted[static_cast<std::size_t>(q * (sorted.size() - 1))];
}

TEST(Lidar, SameSeedGivesBitIdenticalScansWhateverTheThreadCount) {
  const Simulation a(smallScenario(true), 2.0, 4), b(smallScenario(true), 2.0, 4);
  io::Scan one, two;
  tbb::task_arena(1).execute([&] { one = a.lidar().simulateScan(a.scene(), a.motion(), 0, 0.0); });
  tbb::task_arena(2).execute([&] { two = b.lidar().simulateScan(b.scene(), b.motion(), 0, 0.0); });
  ASSERT_GT(one.cloud_in_lidar.size(), 1000u);
  ASSERT_EQ(one.cloud_in_lidar.size(), two.cloud_in_lidar.size());
  EXPECT_EQ(one.cloud_in_lidar.positions, two.cloud_in_lidar.positions);
  EXPECT_EQ(one.cloud_in_lidar.times_s, two.cloud_in_lidar.times_s);
  EXPECT_EQ(one.cloud_in_lidar.intensities, two.cloud_in_lidar.intensities);
  EXPECT_EQ(one.cloud_in_lidar.rings, two.cloud_in_lidar.rings);
  // Another seed is another forest.
  const Simulation c(smallScenario(true), 2.0, 5);
  const io::Scan three = c.lidar().simulateScan(c.scene(), c.motion(), 0, 0.0);
  EXPECT_NE(one.cloud_in_lidar.positions, three.cloud_in_lidar.positions);
}

TEST(Lidar, NoiselessPointsLieOnTheSceneAtTheirColumnsPose) {
  const Simulation sim(smallScenario(false), 2.0, 2);
  const io::Scan scan = sim.lidar().simulateScan(sim.scene(), sim.motion(), 3, 0.3);
  ASSERT_GT(scan.cloud_in_lidar.size(), 3000u);
  const std::vector<double> d = surfaceDistances(sim, scan);
  EXPECT_LT(quantile(d, 0.5), 2e-3);  // float32 geometry only
  EXPECT_LT(quantile(d, 0.99), 1e-2);
  // With a single pose for the whole sweep instead, the motion during the 0.1 s skews the scan.
  const lie::SE3 T_body_lidar = sim.lidar().T_body_lidar();
  const lie::SE3 T_world_body_start = sim.motion().at(scan.t_start_s).T_world_body;
  std::vector<double> skewed;
  for (std::size_t i = 0; i < scan.cloud_in_lidar.size(); ++i) {
    if (scan.cloud_in_lidar.columns[i] < 400) continue;  // late columns: largest skew
    skewed.push_back(sim.scene().distanceToSurface(
        T_world_body_start * (T_body_lidar * scan.cloud_in_lidar.positions[i]), 2.0));
  }
  std::sort(skewed.begin(), skewed.end());
  EXPECT_GT(quantile(skewed, 0.5), 10 * quantile(d, 0.5));
}

TEST(Lidar, NoisyPointsLieOnTheSceneWithinTheRangeNoise) {
  const Simulation sim(smallScenario(true), 2.0, 2);
  const io::Scan scan = sim.lidar().simulateScan(sim.scene(), sim.motion(), 3, 0.3);
  const std::vector<double> d = surfaceDistances(sim, scan);
  const double median = quantile(d, 0.5);
  // Range noise of 1 cm + 0.05 % of the range, seen along the ray: median |error| ~ 0.67 sigma.
  EXPECT_GT(median, 0.003);
  EXPECT_LT(median, 0.03);
}

TEST(Lidar, BeamDivergenceMixesRangesAtEdges) {
  Scenario wide = smallScenario(false);
  wide.lidar.sub_rays = 4;
  wide.lidar.columns = 1024;  // sub-rays are cast where azimuth neighbours jump in range
  Scenario thin = wide;
  thin.lidar.sub_rays = 1;
  const Simulation a(wide, 1.0, 2), b(thin, 1.0, 2);
  auto offSurface = [](const Simulation& sim) {
    const io::Scan scan = sim.lidar().simulateScan(sim.scene(), sim.motion(), 1, 0.1);
    const std::vector<double> d = surfaceDistances(sim, scan);
    return std::count_if(d.begin(), d.end(), [](double x) { return x > 0.05; });
  };
  const auto mixed = offSurface(a), exact = offSurface(b);
  RecordProperty("off_surface_with_divergence", static_cast<int>(mixed));
  RecordProperty("off_surface_without", static_cast<int>(exact));
  EXPECT_LE(exact, 5);
  EXPECT_GT(mixed, 20) << "mixed returns between a stem's edge and its background";
}

TEST(Lidar, StemEdgesGiveMixedReturnsBesideTheStem) {
  // Stems look wider than they are: with divergence, returns float in the air just beside a
  // stem (2-30 cm outside its true surface, at 0.3-6 m) between its edge and its background;
  // without divergence there are none.
  Scenario wide = smallScenario(false);
  wide.lidar.sub_rays = 4;
  wide.lidar.columns = 1024;
  Scenario thin = wide;
  thin.lidar.sub_rays = 1;
  const Simulation a(wide, 1.0, 2), b(thin, 1.0, 2);
  auto besideStems = [](const Simulation& sim) {
    const io::Scan scan = sim.lidar().simulateScan(sim.scene(), sim.motion(), 1, 0.1);
    const lie::SE3 T_body_lidar = sim.lidar().T_body_lidar();
    int floating = 0;
    for (std::size_t i = 0; i < scan.cloud_in_lidar.size(); ++i) {
      const lie::SE3 T_world_body = sim.motion().at(scan.cloud_in_lidar.times_s[i]).T_world_body;
      const Eigen::Vector3d p = T_world_body * (T_body_lidar * scan.cloud_in_lidar.positions[i]);
      for (const Tree& tree : sim.scene().trees()) {
        const double s = p.z() - tree.base_world.z();
        if (s < 0.3 || s > 6.0) continue;
        const double outside_m = (p - tree.axisAt(s)).head<2>().norm() - tree.radiusAt(s);
        if (outside_m > 0.02 && outside_m < 0.3 && sim.scene().distanceToSurface(p, 2.0) > 0.05)
          ++floating;
      }
    }
    return floating;
  };
  const int mixed = besideStems(a), exact = besideStems(b);
  RecordProperty("floating_beside_stems_with_divergence", mixed);
  RecordProperty("floating_beside_stems_without", exact);
  EXPECT_EQ(exact, 0);
  EXPECT_GE(mixed, 10) << "stem edges mixed with their background";
}

TEST(Lidar, ScanTimesColumnsAndReturns) {
  const Simulation sim(smallScenario(true), 2.0, 2);
  const io::Scan scan = sim.lidar().simulateScan(sim.scene(), sim.motion(), 5, 0.5, 100.0);
  const PointCloud& c = scan.cloud_in_lidar;
  ASSERT_TRUE(c.isConsistent());
  EXPECT_DOUBLE_EQ(scan.t_start_s, 100.5);
  EXPECT_NEAR(scan.t_end_s - scan.t_start_s, 0.1 * 511.0 / 512.0, 1e-12);
  EXPECT_TRUE(std::is_sorted(c.times_s.begin(), c.times_s.end()));
  EXPECT_GE(c.times_s.front(), scan.t_start_s);
  EXPECT_LE(c.times_s.back(), scan.t_end_s);
  const double fraction = static_cast<double>(c.size()) / (32.0 * 512.0);
  EXPECT_GT(fraction, 0.4);  // the sky above the canopy gaps and far ground give no return
  EXPECT_LT(fraction, 0.98);
  for (std::size_t i = 0; i < c.size(); ++i) {
    const double range = c.positions[i].norm();
    ASSERT_GT(range, 0.4);
    ASSERT_LT(range, 46.0);
  }
}

TEST(Lidar, BuiltInHeadsAndMetadataFiles) {
  LidarParams params;
  params.beams = 64;
  const LidarGeometry g = loadLidarGeometry(params);  // built in: no file, whatever the directory
  EXPECT_EQ(g.source, "built-in os0-128");
  ASSERT_EQ(g.beam_altitude_deg.size(), 64u);
  EXPECT_DOUBLE_EQ(g.beam_altitude_deg.front(), 45.0);  // OS0: +-45 deg
  EXPECT_DOUBLE_EQ(g.beam_altitude_deg.back(), -45.0);
  // A real OS0-128's metadata: the same head to within its unit's calibration.
  params.metadata_json = "../shared/data/ouster/OS-0-128-U1_v2.3.0_1024x10.json";
  const LidarGeometry real = loadLidarGeometry(params);
  ASSERT_EQ(real.beam_altitude_deg.size(), 64u);
  for (std::size_t i = 0; i < 64; ++i) {
    EXPECT_NEAR(real.beam_altitude_deg[i], g.beam_altitude_deg[i], 1.5) << i;
    EXPECT_NEAR(real.beam_azimuth_deg[i], g.beam_azimuth_deg[i], 2.5) << i;
  }
  EXPECT_LT((g.T_sensor_imu.translation() - real.T_sensor_imu.translation()).norm(), 1e-9);
  EXPECT_LT((g.T_sensor_lidar.translation() - real.T_sensor_lidar.translation()).norm(), 1e-9);
  EXPECT_NEAR(g.lidar_origin_to_beam_origin_m, real.lidar_origin_to_beam_origin_m, 1e-9);
  // A file that is not there, or a model that is not built in, is an error, never a fallback.
  params.metadata_json = "does/not/exist.json";
  EXPECT_THROW(loadLidarGeometry(params), InputError);
  params.metadata_json.clear();
  params.model = "os9-1024";
  EXPECT_THROW(loadLidarGeometry(params), InputError);
}

}  // namespace
}  // namespace taiga::sim
