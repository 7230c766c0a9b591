// The TLS reference cloud: every point on a true surface, the stems near the stations covered,
// thinning that keeps real samples, the same cloud whatever the thread count, and the LAS file.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <tuple>
#include <vector>

#include "taiga/core/errors.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/sim/reference_cloud.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

/// A coarse scanner (0.25 deg, 3 cm voxels) keeps the test fast; the code is the same.
ReferenceCloudParams coarse() {
  ReferenceCloudParams p;
  p.angular_step_deg = 0.25;
  p.voxel_m = 0.03;
  p.station_spacing_m = 12.0;
  return p;
}

const Simulation& simulation() {
  static const Simulation sim(scenarioByName("mixed"), 20.0, 3);
  return sim;
}

TEST(ReferenceCloud, StationsFollowThePathAboveTheGround) {
  const std::vector<Eigen::Vector3d> stations = referenceStations(simulation(), coarse());
  ASSERT_GE(stations.size(), 2u);  // about 25 m walked in 20 s
  for (const Eigen::Vector3d& s : stations) {
    EXPECT_NEAR(s.z() - simulation().scene().terrain().height(s.x(), s.y()), 1.5, 1e-9);
    // Off every stem: the walked path is kept clear.
    EXPECT_GT(simulation().scene().distanceToSurface(s, 0.3), 0.2);
  }
  for (std::size_t i = 1; i < stations.size(); ++i)
    EXPECT_GT((stations[i] - stations[i - 1]).head<2>().norm(), 5.0);
}

TEST(ReferenceCloud, EveryPointLiesOnATrueSurfaceAndStemsAreCovered) {
  const Scene& scene = simulation().scene();
  const std::vector<Eigen::Vector3d> stations = referenceStations(simulation(), coarse());
  const PointCloud cloud = simulateReferenceCloud(scene, stations, coarse());
  ASSERT_GT(cloud.size(), 100000u);
  std::vector<double> d;
  for (const Eigen::Vector3d& p : cloud.positions) d.push_back(scene.distanceToSurface(p, 0.5));
  std::sort(d.begin(), d.end());
  RecordProperty("points", static_cast<int>(cloud.size()));
  RecordProperty("max_surface_distance_um", static_cast<int>(1e6 * d.back()));
  // No noise: on the surface to Embree's single precision (0.11 mm at worst here).
  EXPECT_LT(d[d.size() / 2], 1e-4);
  EXPECT_LT(d.back(), 0.001);

  // Stems at breast height within 10 m of a station: points on their surface (1.2-1.4 m).
  int near = 0, covered = 0;
  for (const Tree& tree : scene.trees()) {
    const Eigen::Vector3d axis = tree.axisAt(1.3);
    double nearest_m = 1e9;
    for (const Eigen::Vector3d& s : stations)
      nearest_m = std::min(nearest_m, (s - axis).head<2>().norm());
    if (nearest_m > 10.0) continue;
    ++near;
    int on_stem = 0;
    for (const Eigen::Vector3d& p : cloud.positions) {
      const double h = p.z() - tree.base_world.z();
      if (h < 1.2 || h > 1.4) continue;
      if (std::abs((p - tree.axisAt(h)).head<2>().norm() - tree.radiusAt(h)) < 0.005) ++on_stem;
    }
    covered += on_stem >= 3 ? 1 : 0;
  }
  RecordProperty("stems_near_stations", near);
  RecordProperty("stems_covered", covered);
  ASSERT_GE(near, 5);
  EXPECT_GE(covered, 0.8 * near) << covered << " of " << near;
}

TEST(ReferenceCloud, ThinningKeepsRealSamplesAndIsDeterministic) {
  const Scene& scene = simulation().scene();
  const std::vector<Eigen::Vector3d> stations = {referenceStations(simulation(), coarse())[0]};
  ReferenceCloudParams all = coarse();
  all.voxel_m = 0.0;
  PointCloud one, two;
  tbb::task_arena(1).execute([&] { one = simulateReferenceCloud(scene, stations, coarse()); });
  tbb::task_arena(2).execute([&] { two = simulateReferenceCloud(scene, stations, coarse()); });
  EXPECT_EQ(one.positions, two.positions);
  EXPECT_EQ(one.intensities, two.intensities);
  const PointCloud raw = simulateReferenceCloud(scene, stations, all);
  ASSERT_LT(one.size(), raw.size());
  // Every kept point is one of the raw samples, and no 3 cm voxel is left with two of them.
  auto key = [](const Eigen::Vector3d& p) { return std::make_tuple(p.x(), p.y(), p.z()); };
  std::set<std::tuple<double, double, double>> raw_set;
  for (const Eigen::Vector3d& p : raw.positions) raw_set.insert(key(p));
  for (const Eigen::Vector3d& p : one.positions) ASSERT_TRUE(raw_set.count(key(p)));
  // The grid starts 100 m outside the plot's corner (reference_cloud.cpp).
  const SceneLayout& layout = scene.layout();
  const Eigen::Vector3d corner(layout.center_world.x() - layout.half_size_m - 100.0,
                               layout.center_world.y() - layout.half_size_m - 100.0, -1000.0);
  std::set<std::tuple<long, long, long>> voxels;
  for (const Eigen::Vector3d& p : one.positions) {
    const Eigen::Vector3d cell = ((p - corner) / 0.03).array().floor();
    voxels.insert({static_cast<long>(cell.x()), static_cast<long>(cell.y()),
                   static_cast<long>(cell.z())});
  }
  EXPECT_EQ(voxels.size(), one.size());
  for (const float intensity : one.intensities) {
    EXPECT_GT(intensity, 0.0f);
    EXPECT_LE(intensity, 50.0f);  // reflectivity <= 0.5, x cos(incidence), percent
  }
}

TEST(ReferenceCloud, WritesALasFileAndRejectsBadParameters) {
  ReferenceCloudParams p = coarse();
  p.angular_step_deg = 0.5;
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("taiga_reference_" + std::to_string(getpid()) + ".las");
  const ReferenceCloudSummary summary = writeReferenceCloud(simulation(), path, p);
  io::LasReader reader(path);
  EXPECT_EQ(reader.pointCount(), summary.points);
  EXPECT_GT(summary.points, 10000u);
  EXPECT_EQ(summary.file_bytes, std::filesystem::file_size(path));
  PointCloud back;
  reader.read(0, 100, back);
  for (std::size_t i = 0; i < back.size(); ++i)
    EXPECT_LT(simulation().scene().distanceToSurface(back.positions[i], 0.5), 0.002);
  std::filesystem::remove(path);

  ReferenceCloudParams bad = coarse();
  bad.angular_step_deg = 0.0;
  EXPECT_THROW(referenceStations(simulation(), bad), InputError);
  bad = coarse();
  bad.voxel_m = -1.0;
  EXPECT_THROW(simulateReferenceCloud(simulation().scene(), {}, bad), InputError);
}

}  // namespace
}  // namespace taiga::sim
