// Map sharpness: hand-computed statistics on a plane, then maps made of simulated lidar returns
// from the true scene: with the true poses the score is the range noise; with poses a few
// centimetres and half a degree off it is clearly larger.
#include "taiga/eval/map_sharpness.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::eval {
namespace {

double distanceToGround(const Eigen::Vector3d& p, double max_m) { return std::min(std::abs(p.z()), max_m); }

TEST(MapSharpness, StatisticsOfCappedDistancesAfterTheAlignment) {
  // Heights 0.1, 0.2, ..., 1.0 and one at 3 m above z = 0, in a frame 5 m above the truth's.
  std::vector<Eigen::Vector3d> points_est;
  for (int i = 1; i <= 10; ++i) points_est.emplace_back(i, 0.0, 5.0 + 0.1 * i);
  points_est.emplace_back(0.0, 0.0, 8.0);
  const AlignmentTransform T{lie::SE3(lie::SO3(), Eigen::Vector3d(0, 0, -5)), 1.0};
  const MapSharpness m = computeMapSharpness(points_est, 1100, T, distanceToGround, {.cap_m = 0.5});
  // Capped: 0.1 0.2 0.3 0.4 0.5 0.5 0.5 0.5 0.5 0.5 0.5.
  const double sum2 = 0.01 + 0.04 + 0.09 + 0.16 + 7 * 0.25;
  EXPECT_NEAR(m.rms_m, std::sqrt(sum2 / 11.0), 1e-12);
  EXPECT_NEAR(m.mean_m, (1.0 + 3.5) / 11.0, 1e-12);
  EXPECT_NEAR(m.median_m, 0.5, 1e-12);
  EXPECT_NEAR(m.fraction_beyond_cap, 6.0 / 11.0, 1e-12);  // 0.6 .. 1.0 and 3 m: 0.5 is not beyond
  EXPECT_EQ(m.points_scored, 11u);
  EXPECT_EQ(m.map_points, 1100u);
  EXPECT_THROW(computeMapSharpness({}, 0, T, distanceToGround), InputError);
}

// Lidar-like returns of the true scene from the poses of a simulated walk, with Gaussian range
// noise, stored per "keyframe" in the body frame.
struct SimulatedMap {
  std::vector<lie::SE3> T_ref_body;                  // true keyframe poses
  std::vector<std::vector<Eigen::Vector3d>> scans;  // body frame
};

SimulatedMap simulateMap(const sim::Simulation& simulation, double range_sigma_m) {
  SimulatedMap map;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, range_sigma_m);
  for (double t_s = 1.0; t_s < 9.5; t_s += 1.0) {
    const lie::SE3 T_world_body = simulation.motion().at(t_s).T_world_body;
    std::vector<Eigen::Vector3d> scan_body;
    // Directions on a grid of azimuth x elevation, as a spinning lidar sees the forest.
    for (int a = 0; a < 180; ++a) {
      for (int e = 0; e < 16; ++e) {
        const double azimuth = 2.0 * a * kRadPerDeg;
        const double elevation = (-45.0 + 4.0 * e) * kRadPerDeg;
        const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth),
                                std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
        const Eigen::Vector3d origin = T_world_body.translation();
        const auto hit = simulation.scene().castRay(origin, d, 0.5, 40.0);
        if (!hit) continue;
        const Eigen::Vector3d p_world = origin + (hit->range_m + noise(rng)) * d;
        scan_body.push_back(T_world_body.inverse() * p_world);
      }
    }
    map.T_ref_body.push_back(T_world_body);
    map.scans.push_back(std::move(scan_body));
  }
  return map;
}

// The map and trajectory as an odometry would give them: in its own world frame (T_est_ref away
// from the truth's), with the given keyframe poses.
MapSharpness score(const sim::Simulation& simulation, const SimulatedMap& map,
                   const std::vector<lie::SE3>& T_ref_body_used) {
  const lie::SE3 T_est_ref(Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ())),
                           Eigen::Vector3d(5.0, -3.0, 1.0));
  std::vector<StampedPose> est, ref;
  std::vector<Eigen::Vector3d> points_est;
  for (std::size_t k = 0; k < map.scans.size(); ++k) {
    const lie::SE3 T_est_body = T_est_ref * T_ref_body_used[k];
    est.push_back({static_cast<double>(k), T_est_body});
    ref.push_back({static_cast<double>(k), map.T_ref_body[k]});
    for (const Eigen::Vector3d& p_body : map.scans[k]) points_est.push_back(T_est_body * p_body);
  }
  const AlignmentTransform T_ref_est = computeAlignment(est, ref, Alignment::kSe3);
  return computeMapSharpness(
      points_est, points_est.size(), T_ref_est,
      [&](const Eigen::Vector3d& p, double max_m) { return simulation.scene().distanceToSurface(p, max_m); });
}

TEST(MapSharpness, TruePosesScoreTheRangeNoiseAndPerturbedPosesScoreClearlyWorse) {
  const sim::Simulation simulation(sim::scenarioByName("handheld-loop"), 10.0, 1);
  const SimulatedMap map = simulateMap(simulation, 0.01);
  ASSERT_GT(map.scans.front().size(), 1000u);

  const MapSharpness sharp = score(simulation, map, map.T_ref_body);
  // Range noise of 1 cm along the ray: the distance to the surface is that noise times the cosine
  // of the incidence angle, so at most 1 cm RMS.
  EXPECT_LT(sharp.rms_m, 0.011);
  EXPECT_GT(sharp.rms_m, 0.003);
  EXPECT_LT(sharp.fraction_beyond_cap, 0.001);

  // Every other keyframe 4 cm and 0.5 deg off.
  std::vector<lie::SE3> perturbed = map.T_ref_body;
  for (std::size_t k = 1; k < perturbed.size(); k += 2) {
    const lie::SE3 error(Eigen::Quaterniond(Eigen::AngleAxisd(
                             0.5 * kRadPerDeg, Eigen::Vector3d(1, 1, 1).normalized())),
                         Eigen::Vector3d(0.03, -0.02, 0.02));
    perturbed[k] = perturbed[k] * error;
  }
  const MapSharpness blurred = score(simulation, map, perturbed);
  RecordProperty("sharp_rms_m", std::to_string(sharp.rms_m));
  RecordProperty("blurred_rms_m", std::to_string(blurred.rms_m));
  EXPECT_GT(blurred.rms_m, 2.0 * sharp.rms_m);
  EXPECT_GT(blurred.rms_m, 0.02);
}

}  // namespace
}  // namespace taiga::eval
