#include "taiga/mapping/stem_constellation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace taiga::mapping {
namespace {

/// Stems scattered over a 60 x 60 m plot, 0.1 stems per m^2 (a thinned pine stand), DBH 10-40 cm.
std::vector<StemMark> randomForest(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-30.0, 30.0), dbh(0.1, 0.4), z(-0.3, 0.3);
  std::vector<StemMark> stems(360);
  for (StemMark& s : stems) s = {{xy(rng), xy(rng), 1.3 + z(rng)}, dbh(rng)};
  return stems;
}

/// The stems within 12 m of `centre`, seen from a keyframe at T_map_keyframe: in its frame, with
/// 3 cm of position noise and 1 cm of DBH noise, a fifth of them missed.
std::vector<StemMark> seenFrom(const std::vector<StemMark>& forest, const lie::SE3& T_map_keyframe,
                               unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.03), dbh_noise(0.0, 0.01);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const lie::SE3 T_keyframe_map = T_map_keyframe.inverse();
  std::vector<StemMark> seen;
  for (const StemMark& s : forest) {
    if ((s.position_m - T_map_keyframe.translation()).head<2>().norm() > 12.0 || u(rng) < 0.2)
      continue;
    const Eigen::Vector3d noisy = s.position_m + Eigen::Vector3d(noise(rng), noise(rng), 0.0);
    seen.push_back({T_keyframe_map * noisy, s.dbh_m + dbh_noise(rng)});
  }
  return seen;
}

TEST(StemConstellation, FindsAKeyframeTurnedAndMovedFarBeyondAWindowSearch) {
  const std::vector<StemMark> forest = randomForest(1);
  for (const double yaw_deg : {70.0, -150.0}) {
    const lie::SE3 T_map_keyframe(
        lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), yaw_deg * std::numbers::pi / 180.0),
        Eigen::Vector3d(6.0, -4.0, 0.2));
    const std::vector<StemMark> seen = seenFrom(forest, T_map_keyframe, 2);
    ASSERT_GE(seen.size(), 20u);
    const std::vector<ConstellationMatch> matches = matchConstellations(seen, forest);
    ASSERT_FALSE(matches.empty());
    const ConstellationMatch& best = matches.front();
    EXPECT_GE(best.inliers, seen.size() * 9 / 10);
    const lie::SE3 error = T_map_keyframe.inverse() * best.T_target_source;
    EXPECT_LT(error.translation().head<2>().norm(), 0.05) << yaw_deg;
    EXPECT_LT(std::abs(error.translation().z()), 0.05);
    EXPECT_LT(error.rotation().Log().norm() * 180.0 / std::numbers::pi, 0.5);
    // A rival, if any, is far weaker.
    if (matches.size() > 1) {
      EXPECT_LT(matches[1].inliers * 3, best.inliers);
    }
  }
}

TEST(StemConstellation, AnotherForestMatchesOnlyByChanceAndWeakly) {
  const std::vector<StemMark> seen =
      seenFrom(randomForest(3), lie::SE3(lie::SO3(), Eigen::Vector3d::Zero()), 4);
  ASSERT_GE(seen.size(), 20u);
  const std::vector<ConstellationMatch> matches = matchConstellations(seen, randomForest(1));
  for (const ConstellationMatch& m : matches) EXPECT_LT(m.inliers, seen.size() / 3);
}

TEST(StemConstellation, MergesTheSameStemSeenFromSeveralKeyframes) {
  const std::vector<StemMark> marks = {
      {{0.0, 0.0, 1.3}, 0.20}, {{0.1, 0.0, 1.4}, 0.22}, {{2.0, 0.0, 1.3}, 0.30}};
  const std::vector<StemMark> merged = mergeStemMarks(marks);
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_NEAR(merged[0].position_m.x(), 0.05, 1e-12);
  EXPECT_NEAR(merged[0].dbh_m, 0.21, 1e-12);
}

}  // namespace
}  // namespace taiga::mapping
