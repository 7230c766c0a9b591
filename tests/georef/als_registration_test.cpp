// A ground map registered to a simulated airborne survey (georef/als_registration.hpp): the
// simulator's terrestrial reference cloud of a plot (the ground map) and its ALS at 5 pulses per
// m^2, the ALS placed in a grid with large coordinates; from a guess 5 m and 5 deg off (a GNSS
// start) the map's pose in the grid is found to decimetres; an ALS tile elsewhere is refused.
#include "taiga/georef/als_registration.hpp"

#include <gtest/gtest.h>

#include "taiga/core/angles.hpp"
#include "taiga/sim/als.hpp"
#include "taiga/sim/reference_cloud.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::georef {
namespace {

struct Plot {
  std::vector<Eigen::Vector3d> map_world;  ///< the ground scanner's points, world frame
  std::vector<Eigen::Vector3d> als_grid;   ///< the airborne survey, in the grid
  lie::SE3 T_grid_world;                   ///< the truth
};

const Plot& plot() {
  static const Plot p = [] {
    const sim::Simulation simulation(sim::scenarioByName("handheld-loop"), 30.0, 5);
    sim::ReferenceCloudParams tls;
    tls.angular_step_deg = 0.3;
    tls.voxel_m = 0.1;
    Plot out;
    out.map_world = sim::simulateReferenceCloud(simulation.scene(),
                                                sim::referenceStations(simulation, tls), tls)
                        .positions;
    const sim::SceneLayout& layout = simulation.scene().layout();
    const sim::AlsReturns als =
        sim::simulateAls(simulation.scene(), layout.center_world, layout.half_size_m, {}, 5);
    out.T_grid_world = lie::SE3(lie::SO3::Exp(Eigen::Vector3d(0.0, 0.0, 0.4)),
                                Eigen::Vector3d(385120.0, 6672340.0, 95.0));
    for (const Eigen::Vector3d& q : als.cloud.positions)
      out.als_grid.push_back(out.T_grid_world * q);
    return out;
  }();
  return p;
}

lie::SE3 offBy(const lie::SE3& T, const Eigen::Vector3d& shift_m, double yaw_deg) {
  return lie::SE3(lie::SO3::Exp(Eigen::Vector3d(0.0, 0.0, yaw_deg * kRadPerDeg)) * T.rotation(),
                  T.translation() + shift_m);
}

/// Within 10 cm horizontally, 5 cm in height and 0.1 deg in heading of the truth (the results
/// are 1-2 cm and 0.02 deg: a broken step is metres off).
void expectPlaced(const AlsRegistration& r, const lie::SE3& T_grid_map_true) {
  ASSERT_TRUE(r.ok) << r.reason;
  const lie::SE3 error = T_grid_map_true.inverse() * r.T_grid_map;
  const Eigen::Vector3d t = T_grid_map_true.rotation() * error.translation();
  EXPECT_LT(t.head<2>().norm(), 0.1) << t.transpose();
  EXPECT_LT(std::abs(t.z()), 0.05) << t.transpose();
  EXPECT_LT(std::abs(error.rotation().Log().z()) * kDegPerRad, 0.1);
  EXPECT_GT(r.coverage, 0.5);
  EXPECT_GT(r.sigma.head<3>().minCoeff(), 0.0);
}

TEST(AlsRegistration, FromAGnssGuessTheMapIsPlacedToCentimetres) {
  const Plot& p = plot();
  expectPlaced(registerToAls(p.map_world, p.als_grid, offBy(p.T_grid_world, {4.0, -3.0, 2.5}, 5.0)),
               p.T_grid_world);
  expectPlaced(
      registerToAls(p.map_world, p.als_grid, offBy(p.T_grid_world, {-3.5, 3.5, -3.0}, -4.0)),
      p.T_grid_world);
}

TEST(AlsRegistration, WithoutGnssFromARoughPose20mAnd18degOff) {
  const Plot& p = plot();
  expectPlaced(
      registerToAls(p.map_world, p.als_grid, offBy(p.T_grid_world, {15.0, -12.0, 4.0}, 18.0),
                    {.search_xy_m = 25.0, .search_yaw_deg = 25.0}),
      p.T_grid_world);
}

TEST(AlsRegistration, AnAlsTileThatDoesNotCoverTheMapIsRefused) {
  const Plot& p = plot();
  std::vector<Eigen::Vector3d> elsewhere;
  for (const Eigen::Vector3d& q : p.als_grid)
    elsewhere.push_back(q + Eigen::Vector3d(500.0, 0.0, 0.0));
  const AlsRegistration r = registerToAls(p.map_world, elsewhere, p.T_grid_world);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("does not cover"), std::string::npos) << r.reason;
}

}  // namespace
}  // namespace taiga::georef
