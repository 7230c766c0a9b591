// Relocalization on synthetic keyframes: a walk around a circle in a small forest whose second
// half is a new map segment (the odometry was lost and started over), placed by dead reckoning
// 3 m and 15 deg away from the truth. The segment is found where it belongs, or refused when
// it is somewhere else or when the forest looks the same in several places; the Mapper ties it
// to the map and the graph moves it there.
#include "taiga/mapping/relocalization.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "../support/temp_dir.hpp"
#include "synthetic_forest.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/mapping/mapper.hpp"

namespace taiga::mapping {
namespace {

using ::testing::HasSubstr;

constexpr std::size_t kKeyframes = 30;
constexpr std::size_t kNewSegment = 20;  // keyframes from here on: segment 1

/// Stems in rows 3 m apart on flat ground, beyond the scans' range: every 3 m step along a row
/// shows the same forest.
std::vector<Eigen::Vector3d> plantedInRows() {
  std::vector<Eigen::Vector3d> points_in_world;
  constexpr double kHalf_m = 45.0;
  for (double x_m = -kHalf_m; x_m <= kHalf_m; x_m += 0.5)
    for (double y_m = -kHalf_m; y_m <= kHalf_m; y_m += 0.5)
      points_in_world.emplace_back(x_m, y_m, 0.0);
  for (double x_m = -kHalf_m; x_m <= kHalf_m; x_m += 3.0)
    for (double y_m = -kHalf_m; y_m <= kHalf_m; y_m += 3.0)
      for (double h_m = 0.0; h_m <= 6.0; h_m += 0.25)
        for (int a = 0; a < 12; ++a) {
          const double azimuth_rad = a * 30.0 * kRadPerDeg;
          points_in_world.emplace_back(x_m + 0.15 * std::cos(azimuth_rad),
                                       y_m + 0.15 * std::sin(azimuth_rad), h_m);
        }
  return points_in_world;
}

class RelocalizationOnAForest : public ::testing::Test {
 protected:
  RelocalizationOnAForest() : T_world_body_true_(forest::circlePath(kKeyframes)) {
    config_.loop_submap_keyframes = 5;
  }

  /// Keyframe scans at the true poses; the new segment's from `new_segment_world`.
  void storeScans(const std::vector<Eigen::Vector3d>& world,
                  const std::vector<Eigen::Vector3d>& new_segment_world) {
    for (std::size_t k = 0; k < kKeyframes; ++k)
      store_.add(static_cast<double>(k), T_world_body_true_[k],
                 forest::scanInBody(k < kNewSegment ? world : new_segment_world,
                                    T_world_body_true_[k], 100 + static_cast<unsigned>(k)));
  }

  /// The odometry's poses: the truth, and the new segment moved as a whole by dead reckoning's
  /// error (in the world frame).
  lie::SE3 odometryPose(std::size_t k) const {
    return k < kNewSegment ? T_world_body_true_[k] : dead_reckoning_error_ * T_world_body_true_[k];
  }

  PoseGraph graph() const {
    PoseGraph graph(config_);
    for (std::size_t k = 0; k < kKeyframes; ++k)
      graph.addKeyframe(odometryPose(k), k >= kNewSegment ? 1 : 0);
    return graph;
  }

  RelocalizationAttempt relocalizeKeyframe(std::size_t current) const {
    const PoseGraph g = graph();
    const Attached attached = [](std::size_t k) { return k < kNewSegment; };
    const std::optional<std::size_t> candidate =
        findRelocalizationCandidate(g, current, attached, config_);
    EXPECT_TRUE(candidate.has_value());
    EXPECT_LT(*candidate, kNewSegment);
    return relocalize(g, store_, current, *candidate, attached, config_, odometry_);
  }

  // 2.4 m and 1.8 m off (3 m), turned 15 deg.
  const lie::SE3 dead_reckoning_error_ = forest::poseAt(2.4, -1.8, 0.0, 15.0 * kRadPerDeg);
  MappingConfig config_;
  const OdometryConfig odometry_;
  const taiga::test::TempDir dir_;
  KeyframeStore store_ =
      KeyframeStore::create(dir_.path(), {.registration_voxel_m = odometry_.voxel_size_m});
  std::vector<lie::SE3> T_world_body_true_;
};

TEST_F(RelocalizationOnAForest, FindsTheNewSegmentWhereItBelongs) {
  const std::vector<Eigen::Vector3d> world = forest::forestInWorld(1);
  storeScans(world, world);
  const std::size_t current = 25;
  const RelocalizationAttempt attempt = relocalizeKeyframe(current);
  ASSERT_TRUE(attempt.accepted) << attempt.note;
  EXPECT_EQ(attempt.link.to, current);
  const lie::SE3 truth =
      T_world_body_true_[attempt.link.from].inverse() * T_world_body_true_[current];
  const registration::Separation error = registration::separation(truth, attempt.link.T_from_to);
  EXPECT_LT(error.m, 0.03);
  EXPECT_LT(error.deg, 0.3);
  // It undoes dead reckoning: at keyframe 25 the error moves the body by about 3 m and 15 deg.
  EXPECT_GT(attempt.correction_m, 2.0);
  EXPECT_NEAR(attempt.correction_deg, 15.0, 0.5);
  EXPECT_GT(attempt.overlap, 0.7);
}

TEST_F(RelocalizationOnAForest, RefusesAKeyframeFromAnotherForest) {
  storeScans(forest::forestInWorld(1), forest::forestInWorld(2));
  const RelocalizationAttempt attempt = relocalizeKeyframe(25);
  EXPECT_FALSE(attempt.accepted);
  EXPECT_NE(attempt.note, "");
  EXPECT_LT(attempt.overlap, 0.5) << attempt.note;  // whatever else stopped it, little fits
}

TEST_F(RelocalizationOnAForest, RefusesAForestThatLooksTheSameEveryThreeMetres) {
  const std::vector<Eigen::Vector3d> rows = plantedInRows();
  storeScans(rows, rows);
  const RelocalizationAttempt attempt = relocalizeKeyframe(25);
  EXPECT_FALSE(attempt.accepted);
  EXPECT_THAT(attempt.note, HasSubstr("ambiguous")) << attempt.note;
  EXPECT_GT(attempt.rival_overlap, 0.5);  // the rival is a good fit too: that is the point
}

// The Mapper: segment 1 is tried instead of loop closures, tied to the map once found, and the
// graph moves all of it there; with relocalization off it stays where dead reckoning put it.
TEST_F(RelocalizationOnAForest, TheMapperMovesTheWholeSegmentOntoTheMap) {
  const std::vector<Eigen::Vector3d> world = forest::forestInWorld(1);
  storeScans(world, world);
  for (const bool on : {true, false}) {
    config_.relocalization = on;
    Mapper mapper(config_, odometry_, store_);
    for (std::size_t k = 0; k < kKeyframes; ++k)
      mapper.addKeyframe(k, static_cast<double>(k), odometryPose(k), k >= kNewSegment ? 1 : 0);
    mapper.finish();
    double largest_m = 0.0;
    for (std::size_t k = 0; k < kKeyframes; ++k)
      largest_m = std::max(
          largest_m,
          (mapper.graph().pose(k).translation() - T_world_body_true_[k].translation()).norm());
    if (on) {
      EXPECT_EQ(mapper.reattachedSegments(), std::vector<std::uint64_t>{1});
      EXPECT_LT(largest_m, 0.05);
      EXPECT_EQ(mapper.loopAttempts().size(), 0u);  // too few keyframes for a loop
    } else {
      EXPECT_TRUE(mapper.relocalizationAttempts().empty());
      EXPECT_GT(largest_m, 2.0);
    }
  }
}

}  // namespace
}  // namespace taiga::mapping
