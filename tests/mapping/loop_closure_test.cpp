// Loop closure on synthetic keyframes, without a simulated run: the candidate search of thesis
// Eq. 38 (nearest admissible keyframe, the recent ones excluded, a radius that grows with the
// path since the candidate up to a cap) on hand-made graphs, and the verification on a small
// synthetic forest seen from a circle that returns to its start with drift on the last keyframe.
#include "taiga/mapping/loop_closure.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "../support/temp_dir.hpp"
#include "synthetic_forest.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/pose_graph.hpp"

namespace taiga::mapping {
namespace {

using ::testing::HasSubstr;

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

// ---------------------------------------------------------------------------------------------
// verifyLoop on a synthetic forest

constexpr std::size_t kReturning = 40;  // the keyframe back at the start

// The mapping side of the verification: 10 recent keyframes excluded and 3 on each side of the
// candidate in its submap, so that 41 keyframes are enough; the thresholds are the defaults.
MappingConfig verifyConfig() {
  MappingConfig config;
  config.loop_exclude_recent_keyframes = 10;
  config.loop_submap_keyframes = 3;
  return config;
}

// Keyframes 0-39 once around a circle of 40 m in a forest, keyframe 40 back near keyframe 0:
// 0.2 m behind it, 0.4 m to the left, turned 8 deg to the left. Scans are stored in the body
// frame at the true poses, each with its own thinning; the returning keyframe sees
// `returning_forest`.
class VerifyLoopOnAForest : public ::testing::Test {
 protected:
  VerifyLoopOnAForest() : T_world_body_true_(forest::circlePath(40)) {
    T_world_body_true_.push_back(T_world_body_true_[0] *
                                 forest::poseAt(-0.2, 0.4, 0.0, 8.0 * kRadPerDeg));
  }

  void storeScans(unsigned returning_forest_seed) {
    const std::vector<Eigen::Vector3d> forest_in_world = forest::forestInWorld(1);
    const std::vector<Eigen::Vector3d> other_forest_in_world =
        forest::forestInWorld(returning_forest_seed);
    for (std::size_t k = 0; k < T_world_body_true_.size(); ++k) {
      const bool returning = k == kReturning;
      store_.add(static_cast<double>(k), T_world_body_true_[k],
                 forest::scanInBody(returning ? other_forest_in_world : forest_in_world,
                                    T_world_body_true_[k], 100 + static_cast<unsigned>(k)));
    }
  }

  // The graph at the true poses but for the returning keyframe, which carries `drift` (in its
  // body frame): what the odometry accumulated around the loop.
  PoseGraph graphWithDrift(const lie::SE3& drift) const {
    PoseGraph graph(config_);
    for (std::size_t k = 0; k < T_world_body_true_.size(); ++k)
      graph.addKeyframe(k == kReturning ? T_world_body_true_[k] * drift : T_world_body_true_[k]);
    return graph;
  }

  lie::SE3 trueLoop() const {
    return T_world_body_true_[0].inverse() * T_world_body_true_[kReturning];
  }

  // 0.3 m (0.24 m forward, 0.18 m to the right) and 2 deg of heading.
  const lie::SE3 drift_ =
      lie::SE3::Exp((lie::Vector6() << 0.24, -0.18, 0.0, 0.0, 0.0, 2.0 * kRadPerDeg).finished());
  const MappingConfig config_ = verifyConfig();
  const OdometryConfig odometry_;
  const taiga::test::TempDir dir_;
  KeyframeStore store_ =
      KeyframeStore::create(dir_.path(), {.registration_voxel_m = odometry_.voxel_size_m});
  std::vector<lie::SE3> T_world_body_true_;
};

TEST_F(VerifyLoopOnAForest, AcceptsTheRevisitAndRecoversTheTrueRelativePose) {
  storeScans(/*returning_forest_seed=*/1);  // the same forest all along
  ASSERT_GT(store_.registrationCloud(kReturning)->size(), 1000u);
  const PoseGraph graph = graphWithDrift(drift_);
  const std::optional<LoopCandidate> candidate = findLoopCandidate(graph, kReturning, config_);
  ASSERT_TRUE(candidate.has_value());
  ASSERT_EQ(candidate->keyframe, 0u);

  const LoopAttempt attempt = verifyLoop(graph, store_, kReturning, *candidate, config_, odometry_);
  EXPECT_TRUE(attempt.accepted) << attempt.note;
  EXPECT_EQ(attempt.note, "");
  EXPECT_EQ(attempt.current, kReturning);
  EXPECT_EQ(attempt.loop.from, 0u);
  EXPECT_EQ(attempt.loop.to, kReturning);
  const lie::Vector6 error = (trueLoop().inverse() * attempt.loop.T_from_to).Log();
  EXPECT_LT(error.head<3>().norm(), 0.03) << error.transpose();
  EXPECT_LT(error.tail<3>().norm() * kDegPerRad, 0.3) << error.transpose();
  // The loop undoes the drift the graph had.
  EXPECT_NEAR(attempt.correction_m, 0.3, 0.03);
  EXPECT_NEAR(attempt.correction_deg, 2.0, 0.3);
  EXPECT_LE(attempt.registration.fitness_m2, config_.loop_max_fitness_m2);
  // Thesis Eq. 36 at the loop's fitness, the heading sigma on all three rotation axes.
  const LidarSigmas sigma = odometry_.lidarSigmas(attempt.registration.fitness_m2);
  EXPECT_DOUBLE_EQ(attempt.loop.covariance(0, 0), sigma.translation_m * sigma.translation_m);
  EXPECT_DOUBLE_EQ(attempt.loop.covariance(3, 3), sigma.heading_rad * sigma.heading_rad);
  EXPECT_DOUBLE_EQ(attempt.loop.covariance(4, 4), sigma.heading_rad * sigma.heading_rad);
  EXPECT_EQ(attempt.loop.covariance(0, 3), 0.0);
}

TEST_F(VerifyLoopOnAForest, RejectsTheCloudOfAnotherPlaceWithANote) {
  storeScans(/*returning_forest_seed=*/2);  // the returning keyframe is somewhere else
  const PoseGraph graph = graphWithDrift(drift_);
  const std::optional<LoopCandidate> candidate = findLoopCandidate(graph, kReturning, config_);
  ASSERT_TRUE(candidate.has_value());

  const LoopAttempt attempt = verifyLoop(graph, store_, kReturning, *candidate, config_, odometry_);
  EXPECT_FALSE(attempt.accepted);
  EXPECT_NE(attempt.note, "");
  // Whatever stopped it, nothing there fits: half the source points are stems that are not.
  EXPECT_GT(attempt.registration.fitness_m2, 10.0 * config_.loop_max_fitness_m2);
}

TEST_F(VerifyLoopOnAForest, RejectsACorrectionBeyondTheSearchRadius) {
  storeScans(1);
  const PoseGraph graph = graphWithDrift(drift_);
  LoopCandidate candidate = *findLoopCandidate(graph, kReturning, config_);
  candidate.search_radius_m = 0.2;  // the 0.3 m correction the registration finds is farther
  const LoopAttempt attempt = verifyLoop(graph, store_, kReturning, candidate, config_, odometry_);
  EXPECT_FALSE(attempt.accepted);
  EXPECT_THAT(attempt.note, HasSubstr("beyond 0.20 m"));
  EXPECT_NEAR(attempt.correction_m, 0.3, 0.03);  // the registration itself worked
}

TEST_F(VerifyLoopOnAForest, RejectsARotationBeyondTheLimit) {
  storeScans(1);
  MappingConfig config = config_;
  config.loop_max_rotation_deg = 1.0;  // the 2 deg correction turns further
  const PoseGraph graph = graphWithDrift(drift_);
  const LoopCandidate candidate = *findLoopCandidate(graph, kReturning, config);
  const LoopAttempt attempt = verifyLoop(graph, store_, kReturning, candidate, config, odometry_);
  EXPECT_FALSE(attempt.accepted);
  EXPECT_THAT(attempt.note, HasSubstr("/ 1.0 deg"));
  EXPECT_NEAR(attempt.correction_deg, 2.0, 0.3);
}

}  // namespace
}  // namespace taiga::mapping
