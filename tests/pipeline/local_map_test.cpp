// LocalMap::repose (issue 7: the local map rebuilt from corrected poses): after a keyframe is
// moved, the very next registration uses the map at the new pose, not the structures built before.
#include "taiga/pipeline/local_map.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace taiga::pipeline {
namespace {

// A corner of a room, 0.1 m apart: floor and two walls fix all six degrees of freedom.
std::vector<Eigen::Vector3d> roomCorner() {
  std::vector<Eigen::Vector3d> points;
  for (double a = 0.05; a < 8.0; a += 0.1) {
    for (double b = 0.05; b < 8.0; b += 0.1) {
      points.emplace_back(a, b, 0.0);
      points.emplace_back(a, 0.0, b * 0.5);
      points.emplace_back(0.0, a, b * 0.5);
    }
  }
  return points;
}

lie::SE3 registerFrom(LocalMap& map, const std::vector<Eigen::Vector3d>& source,
                      const lie::SE3& guess) {
  map.beginRegistration();
  registration::NdtConfig ndt;
  ndt.resolution_m = 1.0;
  return registration::alignNdt(source, *map.ndtTargets().back(), guess, ndt).T_target_source;
}

TEST(LocalMap, ReposedKeyframesAreWhatTheNextRegistrationSees) {
  const std::vector<Eigen::Vector3d> corner = roomCorner();
  LocalMap map({1.0}, 0.2, 10, LocalMap::Target::kNdt);
  map.addKeyframe(0, lie::SE3(), corner);
  const lie::SE3 small_error(lie::SO3::fromRollPitchYaw(0.0, 0.0, 0.01), {0.1, -0.08, 0.05});
  EXPECT_LT(registerFrom(map, corner, small_error).translation().norm(), 0.01);

  // A second keyframe far away: the next registration would still use the structures built
  // before it (kScansOnPreviousMap), unless a repose forces the new ones.
  const lie::SE3 T_far(lie::SO3(), {100.0, 0.0, 0.0});
  map.addKeyframe(1, T_far, corner);

  // The graph moves the first keyframe 0.6 m and 3 deg: a scan of the corner now registers there.
  const lie::SE3 T_new_keyframe(lie::SO3::fromRollPitchYaw(0.0, 0.0, 0.05), {0.6, 0.3, 0.0});
  std::vector<std::uint64_t> seen_ids;
  map.repose([&](std::uint64_t id, const lie::SE3& T_old) {
    seen_ids.push_back(id);
    return id == 0 ? T_new_keyframe : T_old;
  });
  EXPECT_EQ(seen_ids, (std::vector<std::uint64_t>{0, 1}));  // oldest first
  const lie::SE3 found = registerFrom(map, corner, T_new_keyframe * small_error);
  EXPECT_LT((found.translation() - T_new_keyframe.translation()).norm(), 0.01);
  EXPECT_LT((found.rotation().inverse() * T_new_keyframe.rotation()).angle(), 0.002);
}

TEST(LocalMap, ReposingInPlaceKeepsTheMap) {
  const std::vector<Eigen::Vector3d> corner = roomCorner();
  LocalMap map({1.0}, 0.2, 10, LocalMap::Target::kNdt);
  map.addKeyframe(0, lie::SE3(), corner);
  map.addKeyframe(1, lie::SE3(lie::SO3(), {0.5, 0.0, 0.0}), corner);
  const lie::SE3 guess(lie::SO3(), {0.2, 0.1, 0.0});
  for (int i = 0; i < LocalMap::kScansOnPreviousMap; ++i)
    registerFrom(map, corner, guess);  // on the structures without the second keyframe
  const lie::SE3 before = registerFrom(map, corner, guess);
  const std::size_t points = map.numPoints();
  map.repose([](std::uint64_t, const lie::SE3& T_old) { return T_old; });
  EXPECT_EQ(map.numPoints(), points);
  EXPECT_LT((registerFrom(map, corner, guess).translation() - before.translation()).norm(), 1e-9);
}

// Upright poles of 10 cm radius on a 3 m grid, over a floor: a scene whose fine cells are narrow
// basins horizontally.
std::vector<Eigen::Vector3d> polesOnAFloor() {
  std::vector<Eigen::Vector3d> points;
  for (double x = 0.05; x < 12.0; x += 0.1)
    for (double y = 0.05; y < 12.0; y += 0.1) points.emplace_back(x, y, 0.0);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      // Off the grid by a few decimetres, so that no shift by the spacing matches.
      const Eigen::Vector2d centre(1.5 + 3.0 * i + 0.1 * j, 1.5 + 3.0 * j + 0.15 * i);
      for (double z = 0.1; z < 3.0; z += 0.1)
        for (double a = 0.0; a < 2.0 * M_PI; a += 0.2)
          points.emplace_back(centre.x() + 0.1 * std::cos(a), centre.y() + 0.1 * std::sin(a), z);
    }
  }
  return points;
}

// A map that keeps only fine cells (with an IMU) serves a guess that may be far off (across a gap
// in the IMU readings) with coarse cells over its points: built on demand, for the map in use.
TEST(LocalMap, CoarseCellsOverItsPointsWidenAFineMapsBasin) {
  const std::vector<Eigen::Vector3d> scene = polesOnAFloor();
  LocalMap map({0.5}, 0.2, 10, LocalMap::Target::kNdt);
  map.addKeyframe(0, lie::SE3(), scene);
  map.beginRegistration();
  const lie::SE3 far_guess(lie::SO3::fromRollPitchYaw(0.0, 0.0, 0.2), {1.3, -1.0, 0.3});
  registration::NdtConfig ndt;
  ndt.resolution_m = 0.5;
  const auto coarseToFine = [&](const lie::SE3& guess) {
    const lie::SE3 coarse =
        registration::alignNdt(scene, map.coarseNdtTarget(2.0), guess, ndt).T_target_source;
    return registration::alignNdt(scene, *map.ndtTargets().back(), coarse, ndt).T_target_source;
  };
  const double fine_alone_m =
      registration::alignNdt(scene, *map.ndtTargets().back(), far_guess, ndt)
          .T_target_source.translation()
          .norm();
  EXPECT_GT(fine_alone_m, 0.1);
  EXPECT_LT(coarseToFine(far_guess).translation().norm(), 0.01);
  EXPECT_EQ(map.coarseNdtTarget(2.0).resolution_m(), 2.0);

  // Moved by a repose, the coarse cells are those of the map in use, not the ones built before.
  const lie::SE3 T_moved(lie::SO3(), {1.7, 0.0, 0.0});
  map.repose([&](std::uint64_t, const lie::SE3&) { return T_moved; });
  map.beginRegistration();
  EXPECT_LT((coarseToFine(T_moved * far_guess).translation() - T_moved.translation()).norm(), 0.01);
}

}  // namespace
}  // namespace taiga::pipeline
