// Loop closure on synthetic keyframes, without a simulated run: the candidate search of thesis
// Eq. 38 (nearest admissible keyframe, the recent ones excluded, a radius that grows with the
// path since the candidate up to a cap) on hand-made graphs.
#include "taiga/mapping/loop_closure.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "taiga/mapping/pose_graph.hpp"

namespace taiga::mapping {
namespace {

// ---------------------------------------------------------------------------------------------
// findLoopCandidate

// Keyframes on straight legs through `corners_m` (x, y; z = 0), at most 1 m apart and evenly
// spaced on each leg, the first on corners_m[0] and one on every corner. The heading does not
// matter to the search and stays 0.
PoseGraph graphThrough(const std::vector<Eigen::Vector2d>& corners_m, const MappingConfig& config) {
  PoseGraph graph(config);
  graph.addKeyframe(lie::SE3(lie::SO3(), Eigen::Vector3d(corners_m[0].x(), corners_m[0].y(), 0)));
  for (std::size_t c = 1; c < corners_m.size(); ++c) {
    const Eigen::Vector2d leg_m = corners_m[c] - corners_m[c - 1];
    const int steps = static_cast<int>(std::ceil(leg_m.norm() - 1e-9));
    for (int i = 1; i <= steps; ++i) {
      const Eigen::Vector2d p_m = corners_m[c - 1] + leg_m * (static_cast<double>(i) / steps);
      graph.addKeyframe(lie::SE3(lie::SO3(), Eigen::Vector3d(p_m.x(), p_m.y(), 0.0)));
    }
  }
  return graph;
}

// Small numbers so that the graphs stay small: 10 recent keyframes excluded, a 2 m radius that
// grows by 2 cm per metre of path, capped at 4 m.
MappingConfig candidateConfig() {
  MappingConfig config;
  config.loop_exclude_recent_keyframes = 10;
  config.loop_search_radius_m = 2.0;
  config.loop_radius_growth_m_per_m = 0.02;
  config.loop_max_search_radius_m = 4.0;
  return config;
}

std::size_t last(const PoseGraph& graph) { return graph.size() - 1; }

TEST(FindLoopCandidate, IsTheNearestAdmissibleKeyframe) {
  const MappingConfig config = candidateConfig();
  // Up 20 m along y, 1.2 m across, and back down to y = 10: the walk ends 1.2 m beside
  // keyframe 10, at (0, 10); its neighbours 9 and 11 are within the radius too, but farther.
  const PoseGraph graph = graphThrough({{0, 0}, {0, 20}, {1.2, 20}, {1.2, 10}}, config);
  ASSERT_EQ(graph.size(), 33u);
  ASSERT_LT((graph.pose(10).translation() - Eigen::Vector3d(0, 10, 0)).norm(), 1e-9);

  const std::optional<LoopCandidate> candidate = findLoopCandidate(graph, last(graph), config);
  ASSERT_TRUE(candidate.has_value());
  EXPECT_EQ(candidate->keyframe, 10u);
  EXPECT_NEAR(candidate->distance_m, 1.2, 1e-9);
  const double path_since_m = graph.pathLength(last(graph)) - graph.pathLength(10);
  EXPECT_NEAR(path_since_m, 10.0 + 1.2 + 10.0, 1e-9);
  EXPECT_NEAR(candidate->search_radius_m, 2.0 + 0.02 * path_since_m, 1e-9);
}

TEST(FindLoopCandidate, TheMostRecentKeyframesAreNeverCandidates) {
  // A straight line, keyframes 1 m apart: keyframe k is (30 - k) m behind keyframe 30. With no
  // growth and a 12 m radius, the candidate is the newest admissible keyframe, 30 - excluded.
  MappingConfig config = candidateConfig();
  config.loop_radius_growth_m_per_m = 0.0;
  config.loop_search_radius_m = 12.0;
  config.loop_max_search_radius_m = 12.0;
  const PoseGraph graph = graphThrough({{0, 0}, {30, 0}}, config);
  ASSERT_EQ(graph.size(), 31u);
  for (const int excluded : {1, 5, 10, 11}) {
    config.loop_exclude_recent_keyframes = excluded;
    const std::optional<LoopCandidate> candidate = findLoopCandidate(graph, 30, config);
    ASSERT_TRUE(candidate.has_value()) << excluded;
    EXPECT_EQ(candidate->keyframe, 30u - static_cast<std::size_t>(excluded)) << excluded;
    EXPECT_NEAR(candidate->distance_m, excluded, 1e-9);
  }
  config.loop_exclude_recent_keyframes = 13;  // the newest admissible one is 13 m away
  EXPECT_FALSE(findLoopCandidate(graph, 30, config).has_value());
}

TEST(FindLoopCandidate, StandingStillTheFirstCandidateComesAfterTheExcludedKeyframes) {
  const MappingConfig config = candidateConfig();  // 10 excluded
  PoseGraph graph(config);
  for (int k = 0; k < 11; ++k) graph.addKeyframe(lie::SE3());
  for (std::size_t current = 0; current < 10; ++current)
    EXPECT_FALSE(findLoopCandidate(graph, current, config).has_value()) << current;
  const std::optional<LoopCandidate> candidate = findLoopCandidate(graph, 10, config);
  ASSERT_TRUE(candidate.has_value());
  EXPECT_EQ(candidate->keyframe, 0u);
  EXPECT_EQ(candidate->distance_m, 0.0);
  EXPECT_EQ(candidate->search_radius_m, 2.0);  // no path, no growth
}

// Up H m along y, `gap_m` across, and back down to y = 0: the walk ends gap_m beside keyframe 0
// after a path of 2 H + gap_m. Every other admissible keyframe is farther.
PoseGraph returnBeside(double up_m, double gap_m, const MappingConfig& config) {
  return graphThrough({{0, 0}, {0, up_m}, {gap_m, up_m}, {gap_m, 0}}, config);
}

TEST(FindLoopCandidate, TheRadiusGrowsWithThePathSinceTheCandidate) {
  const MappingConfig config = candidateConfig();  // 2 m + 0.02 m/m, at most 4 m
  // 3 m beside the start, outside the 2 m base radius.
  const PoseGraph short_walk = returnBeside(10.0, 3.0, config);  // radius 2 + 0.02 * 23 = 2.46 m
  EXPECT_FALSE(findLoopCandidate(short_walk, last(short_walk), config).has_value());

  const PoseGraph long_walk = returnBeside(40.0, 3.0, config);  // radius 2 + 0.02 * 83 = 3.66 m
  const std::optional<LoopCandidate> candidate =
      findLoopCandidate(long_walk, last(long_walk), config);
  ASSERT_TRUE(candidate.has_value());
  EXPECT_EQ(candidate->keyframe, 0u);
  EXPECT_NEAR(candidate->distance_m, 3.0, 1e-9);
  EXPECT_NEAR(candidate->search_radius_m, 3.66, 1e-9);
}

TEST(FindLoopCandidate, TheGrownRadiusIsCappedAtTheMaximum) {
  MappingConfig config = candidateConfig();  // at most 4 m
  // After 400 m of path the grown radius would be 2 + 0.02 * 404 = 10 m.
  const PoseGraph inside_cap = returnBeside(200.0, 3.9, config);
  const std::optional<LoopCandidate> candidate =
      findLoopCandidate(inside_cap, last(inside_cap), config);
  ASSERT_TRUE(candidate.has_value());
  EXPECT_EQ(candidate->keyframe, 0u);
  EXPECT_EQ(candidate->search_radius_m, 4.0);

  const PoseGraph beyond_cap = returnBeside(200.0, 4.5, config);
  EXPECT_FALSE(findLoopCandidate(beyond_cap, last(beyond_cap), config).has_value());
  // Only the cap keeps it out: with a higher one the same keyframe is found.
  config.loop_max_search_radius_m = 30.0;
  const std::optional<LoopCandidate> uncapped =
      findLoopCandidate(beyond_cap, last(beyond_cap), config);
  ASSERT_TRUE(uncapped.has_value());
  EXPECT_EQ(uncapped->keyframe, 0u);
  EXPECT_NEAR(uncapped->search_radius_m, 2.0 + 0.02 * beyond_cap.pathLength(last(beyond_cap)),
              1e-9);
}

TEST(FindLoopCandidate, NoneWhenNoAdmissibleKeyframeIsWithinTheRadius) {
  const MappingConfig config;  // the defaults: 40 excluded, 5 m + 0.02 m/m
  const PoseGraph graph = graphThrough({{0, 0}, {100, 0}}, config);
  EXPECT_FALSE(findLoopCandidate(graph, last(graph), config).has_value());
}

}  // namespace
}  // namespace taiga::mapping
