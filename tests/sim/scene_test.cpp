// Scenes: determinism, statistics per scenario, ray casting and distances at known geometry.
#include "taiga/sim/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "taiga/core/angles.hpp"
#include "taiga/sim/gnss.hpp"
#include "taiga/sim/scenario.hpp"

namespace taiga::sim {
namespace {

SceneLayout smallLayout(double half_size_m = 25.0) {
  SceneLayout layout;
  layout.half_size_m = half_size_m;
  for (int i = 0; i < 100; ++i) layout.keep_out_path.emplace_back(-10.0 + 0.2 * i, 0.0);
  return layout;
}

/// Only birches (no dead twigs below their crowns) and nothing else: clear views of the stems.
ForestParams bareBirches() {
  ForestParams p;
  p.stems_per_ha = 150;
  p.species = {0.0, 0.0, 1.0};
  p.saplings_per_ha = p.shrubs_per_ha = p.boulders_per_ha = p.logs_per_ha = 0.0;
  return p;
}

TEST(Scene, SameSeedGivesTheSameSceneAndAnotherSeedAnother) {
  const ForestParams params = scenarioByName("mixed").forest;
  const Scene a(params, 7, smallLayout()), b(params, 7, smallLayout()), c(params, 8, smallLayout());
  ASSERT_EQ(a.trees().size(), b.trees().size());
  EXPECT_EQ(a.stats().triangles, b.stats().triangles);
  EXPECT_EQ(a.stats().curve_segments, b.stats().curve_segments);
  for (std::size_t i = 0; i < a.trees().size(); ++i) {
    EXPECT_EQ(a.trees()[i].base_world, b.trees()[i].base_world);
    EXPECT_EQ(a.trees()[i].dbh_m, b.trees()[i].dbh_m);
    EXPECT_EQ(a.trees()[i].height_m, b.trees()[i].height_m);
  }
  ASSERT_FALSE(c.trees().empty());
  EXPECT_NE(a.trees().front().base_world, c.trees().front().base_world);
  // Same rays, same answers.
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d origin(0.0, 0.0, a.terrain().height(0, 0) + 2.0);
    const double az = 0.1 * i;
    const Eigen::Vector3d d(std::cos(az), std::sin(az), -0.1);
    const auto ha = a.castRay(origin, d.normalized(), 0.0, 50.0),
               hb = b.castRay(origin, d.normalized(), 0.0, 50.0);
    ASSERT_EQ(ha.has_value(), hb.has_value());
    if (ha) {
      EXPECT_EQ(ha->range_m, hb->range_m);
    }
  }
}

TEST(Scene, StandStatisticsMatchTheScenario) {
  for (const std::string name : {"sparse_pine", "mixed", "dense_spruce"}) {
    SCOPED_TRACE(name);
    const ForestParams params = scenarioByName(name).forest;
    const Scene scene(params, 3, smallLayout(30.0));
    const double density = static_cast<double>(scene.trees().size()) / scene.stats().area_ha;
    EXPECT_GT(density, 0.85 * params.stems_per_ha);
    EXPECT_LE(density, 1.0 * params.stems_per_ha + 1.0);
    EXPECT_GE(density, 400.0);
    EXPECT_LE(density, 1500.0);
    double dbh_sum = 0.0;
    for (const Tree& t : scene.trees()) {
      EXPECT_GE(t.dbh_m, 0.08);
      EXPECT_LE(t.dbh_m, 0.50);
      EXPECT_GE(t.height_m, 10.0);
      EXPECT_LE(t.height_m, 28.0);
      EXPECT_LE(t.lean_rad, 8.0 * kRadPerDeg);
      EXPECT_LT(t.crown_base_m, t.height_m);
      // Stems stand on the ground and off the walked path (the x axis from -10 to 10 m).
      EXPECT_NEAR(t.base_world.z(), scene.terrain().height(t.base_world.x(), t.base_world.y()),
                  1e-9);
      if (std::abs(t.base_world.x()) < 9.0) {
        EXPECT_GT(std::abs(t.base_world.y()), params.path_clearance_m);
      }
      dbh_sum += t.dbh_m;
    }
    EXPECT_NEAR(dbh_sum / scene.trees().size(), params.dbh_mean_m, 0.03);
  }
  const Scene open(scenarioByName("open_field").forest, 3, smallLayout(30.0));
  EXPECT_LT(open.trees().size(), 3u);
}

TEST(Scene, StripRoadHasNoStemsOnTheRoad) {
  const ForestParams params = scenarioByName("strip_road").forest;
  const Scene scene(params, 5, smallLayout(30.0));
  ASSERT_GT(scene.trees().size(), 100u);
  for (const Tree& t : scene.trees())
    EXPECT_GT(std::abs(t.base_world.y()), params.road_half_width_m);
}

/// The stem at breast height seen horizontally from `distance_m` away, from a side with no other
/// stem near the line of sight; nullopt when the tree has no such side.
struct StemView {
  Eigen::Vector3d origin, direction;
  double expected_range_m;
};
std::optional<StemView> viewOfStem(const Scene& scene, const Tree& tree, double distance_m) {
  const Eigen::Vector3d axis = tree.axisAt(1.3);
  for (int k = 0; k < 8; ++k) {
    const double az = k * std::numbers::pi / 4;
    const Eigen::Vector3d d(std::cos(az), std::sin(az), 0.0);
    const Eigen::Vector3d origin = axis - distance_m * d;
    bool clear = std::abs(origin.x()) < 20 && std::abs(origin.y()) < 20 &&
                 scene.terrain().height(origin.x(), origin.y()) < origin.z() - 0.3;
    for (const Tree& other : scene.trees()) {
      if (&other == &tree) continue;
      const Eigen::Vector3d rel = other.base_world - origin;
      const double along = rel.head<2>().dot(d.head<2>());
      const double across = std::abs(rel.x() * d.y() - rel.y() * d.x());
      if (along > -1.0 && along < distance_m + 1.0 && across < 1.0) clear = false;
    }
    if (clear) return StemView{origin, d, distance_m - tree.radiusAt(1.3)};
  }
  return std::nullopt;
}

TEST(Scene, RayAtAKnownStemHitsItsBarkAtTheExpectedRange) {
  const Scene scene(bareBirches(), 11, smallLayout());
  int checked = 0;
  for (const Tree& tree : scene.trees()) {
    const auto view = viewOfStem(scene, tree, 4.0);
    if (!view) continue;
    const auto hit = scene.castRay(view->origin, view->direction, 0.0, 10.0);
    ASSERT_TRUE(hit.has_value());
    // A leaning stem's horizontal section is slightly elliptic (lean <= 8 deg: < 1 % of the
    // radius).
    EXPECT_NEAR(hit->range_m, view->expected_range_m, 0.005);
    EXPECT_EQ(hit->material, Material::kBark);
    EXPECT_LT(hit->normal_world.dot(view->direction), -0.98);  // faces the ray
    // The stem is 1.3 m above the ground on its axis.
    EXPECT_NEAR(tree.axisAt(1.3).z() - tree.base_world.z(), 1.3, 1e-12);
    ++checked;
  }
  EXPECT_GT(checked, 5);
}

TEST(Scene, DistanceToSurfaceNearStemsAndGround) {
  const Scene scene(bareBirches(), 11, smallLayout());
  int checked = 0;
  for (const Tree& tree : scene.trees()) {
    const auto view = viewOfStem(scene, tree, 4.0);
    if (!view) continue;
    const Eigen::Vector3d on_bark = view->origin + view->expected_range_m * view->direction;
    EXPECT_NEAR(scene.distanceToSurface(on_bark - 0.5 * view->direction), 0.5, 0.01);
    EXPECT_LT(scene.distanceToSurface(on_bark), 0.005);
    EXPECT_NEAR(scene.distanceToSurface(tree.axisAt(1.3)), tree.radiusAt(1.3),
                0.005);  // inside: unsigned
    ++checked;
  }
  EXPECT_GT(checked, 5);
  // Above open ground: the height above the (gently sloping) terrain, to within the slope's cosine.
  const Eigen::Vector3d above(0.0, 0.0, scene.terrain().height(0.0, 0.0) + 0.4);
  const double d = scene.distanceToSurface(above);
  EXPECT_LE(d, 0.4 + 1e-3);
  EXPECT_GT(d, 0.3);
  EXPECT_DOUBLE_EQ(scene.distanceToSurface(Eigen::Vector3d(0, 0, 500.0), 5.0), 5.0);
}

TEST(Geodesy, EnuToGeodeticIsExactAndInvertible) {
  const Geodetic origin{61.0, 24.5, 120.0};
  const Geodetic same = enuToGeodetic(origin, Eigen::Vector3d::Zero());
  EXPECT_NEAR(same.latitude_deg, 61.0, 1e-12);
  EXPECT_NEAR(same.longitude_deg, 24.5, 1e-12);
  EXPECT_NEAR(same.height_m, 120.0, 1e-6);
  // 1 km north: the WGS84 meridian radius of curvature at 61 N is 6 384 418 m (a(1-e2)/W^3).
  const Geodetic north = enuToGeodetic(origin, Eigen::Vector3d(0, 1000, 0));
  EXPECT_NEAR(north.latitude_deg - 61.0, 1000.0 / 6384418.0 * kDegPerRad, 2e-7);
  const Eigen::Vector3d p(-321.5, 845.25, 12.5);
  EXPECT_LT((geodeticToEnu(origin, enuToGeodetic(origin, p)) - p).norm(), 1e-6);
}

}  // namespace
}  // namespace taiga::sim
