// The correlative search over heading and horizontal position (correlative_search.hpp): on the
// real HDL-32E pair turned 20-45 deg and shifted, its best start lies within a grid step of the
// truth, close enough for NDT to finish; the same answer with one thread as with many; and the
// occupancy it scores against.
#include "taiga/registration/correlative_search.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "registration_data.hpp"
#include "taiga/registration/registration.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration {
namespace {

struct RealPair {
  std::vector<Eigen::Vector3d> source =
      voxelDownsample(test::loadPositions(test::kRegistrationData / "source.ply"), 0.25);
  std::vector<Eigen::Vector3d> target = test::loadPositions(test::kRegistrationData / "target.ply");
  lie::SE3 reference = test::loadTransform(test::kRegistrationData / "T_target_source.txt");

  /// The source moved by `move` (points move * p), and the transform that then aligns it.
  std::vector<Eigen::Vector3d> moved(const lie::SE3& move) const {
    std::vector<Eigen::Vector3d> points;
    for (const Eigen::Vector3d& p : source) points.push_back(move * p);
    return points;
  }
  lie::SE3 truthAfter(const lie::SE3& move) const { return reference * move.inverse(); }
};

lie::SE3 turnAndShift(double yaw_deg, double x_m, double y_m) {
  return lie::SE3(lie::SO3::fromRollPitchYaw(0.0, 0.0, yaw_deg * kRadPerDeg),
                  Eigen::Vector3d(x_m, y_m, 0.0));
}

TEST(CorrelativeSearch, TheBestStartOfTheTurnedRealPairIsNearTheTruthAndNdtFinishesIt) {
  const RealPair pair;
  const Occupancy occupancy(pair.target, CorrelativeWindow{}.voxel_m);
  RegistrationConfig ndt;
  ndt.ndt.coarse_resolutions_m = {2.0};
  for (const lie::SE3& move : {turnAndShift(20.0, 0.3, -0.2), turnAndShift(-35.0, -0.4, 0.1),
                               turnAndShift(45.0, 0.0, 0.5), turnAndShift(-45.0, 0.2, 0.2)}) {
    const std::vector<Eigen::Vector3d> source = pair.moved(move);
    const lie::SE3 truth = pair.truthAfter(move);
    const std::vector<CorrelativeCandidate> starts =
        correlativeSearch(source, occupancy, lie::SE3(), {}, 3);
    ASSERT_EQ(starts.size(), 3u);
    EXPECT_GE(starts[0].score, starts[1].score);
    EXPECT_GE(starts[1].score, starts[2].score);
    // Within about a grid step (2 deg, 0.2 m) and the truth's own small roll and pitch.
    const test::PoseError start_error = test::poseError(starts[0].T_target_source, truth);
    EXPECT_LT(start_error.rotation_deg, 3.0) << move.rotation().Log().z() * kDegPerRad;
    EXPECT_LT(start_error.translation_m, 0.3);
    const RegistrationResult refined =
        registerClouds(source, pair.target, starts[0].T_target_source, ndt);
    const test::PoseError e = test::poseError(refined.T_target_source, truth);
    EXPECT_LT(e.translation_m, 0.05);
    EXPECT_LT(e.rotation_deg, 0.5);
  }
}

TEST(CorrelativeSearch, StartsAreDistinctAndTheAnswerDoesNotDependOnTheThreads) {
  const RealPair pair;
  const Occupancy occupancy(pair.target, 0.5);
  const std::vector<Eigen::Vector3d> source = pair.moved(turnAndShift(30.0, 0.0, 0.0));
  const auto search = [&] { return correlativeSearch(source, occupancy, lie::SE3(), {}, 5); };
  const std::vector<CorrelativeCandidate> many = search();
  std::vector<CorrelativeCandidate> one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = search();
  }
  ASSERT_EQ(many.size(), one.size());
  for (std::size_t i = 0; i < many.size(); ++i) {
    EXPECT_EQ(many[i].score, one[i].score);
    EXPECT_TRUE(many[i].T_target_source.matrix().isApprox(one[i].T_target_source.matrix()));
    for (std::size_t j = 0; j < i; ++j) {
      const lie::SE3 d = many[j].T_target_source.inverse() * many[i].T_target_source;
      const bool apart = std::abs(d.rotation().Log().z()) * kDegPerRad > 4.0 + 1e-6 ||
                         std::abs(many[i].T_target_source.translation().x() -
                                  many[j].T_target_source.translation().x()) > 0.4 + 1e-6 ||
                         std::abs(many[i].T_target_source.translation().y() -
                                  many[j].T_target_source.translation().y()) > 0.4 + 1e-6;
      EXPECT_TRUE(apart) << i << " and " << j;
    }
  }
}

TEST(CorrelativeSearch, OccupancyMarksTheVoxelsOfTheTargetPointsOnly) {
  const std::vector<Eigen::Vector3d> target = {{0.1, 0.1, 0.1}, {2.3, -0.2, 0.4}, {0.2, 0.3, 0.4}};
  const Occupancy occupancy(target, 0.5);
  EXPECT_TRUE(occupancy.occupied({0.4, 0.3, 0.2}));
  EXPECT_TRUE(occupancy.occupied({2.4, -0.4, 0.3}));
  EXPECT_FALSE(occupancy.occupied({0.6, 0.1, 0.1}));
  EXPECT_FALSE(occupancy.occupied({0.1, 0.1, -0.1}));
  EXPECT_FALSE(occupancy.occupied({std::nan(""), 0.0, 0.0}));
}

TEST(CorrelativeSearch, AnEmptySourceOrTargetGivesNoStartOrAZeroScore) {
  const Occupancy empty(std::vector<Eigen::Vector3d>{}, 0.5);
  const std::vector<Eigen::Vector3d> source = {{1.0, 0.0, 0.0}};
  EXPECT_TRUE(correlativeSearch({}, empty, lie::SE3(), {}, 3).empty());
  const std::vector<CorrelativeCandidate> starts =
      correlativeSearch(source, empty, lie::SE3(), {}, 1);
  ASSERT_EQ(starts.size(), 1u);
  EXPECT_EQ(starts[0].score, 0.0);
}

}  // namespace
}  // namespace taiga::registration
