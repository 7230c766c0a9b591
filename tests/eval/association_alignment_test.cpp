// Time association (evo's associate_trajectories) and alignment (Umeyama, origin).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>

#include "../support/temp_dir.hpp"
#include "eval_test_support.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/eval/alignment.hpp"
#include "taiga/eval/association.hpp"

namespace taiga::eval {
namespace {

using ::testing::HasSubstr;

Trajectory stampsOnly(const std::vector<double>& stamps) {
  std::vector<StampedPose> poses;
  for (const double t : stamps) poses.push_back({t, lie::SE3(lie::SO3(), {t, 0.0, 0.0})});
  return Trajectory(poses);
}

std::vector<double> times(const std::vector<StampedPose>& poses) {
  std::vector<double> t;
  for (const StampedPose& p : poses) t.push_back(p.t_s);
  return t;
}

TEST(Association, NearestStampIsTheFirstOnATie) {
  EXPECT_EQ(nearestStampIndex({0.0, 1.0, 2.0}, 0.5), 0u);
  EXPECT_EQ(nearestStampIndex({0.0, 1.0, 2.0}, 0.51), 1u);
  EXPECT_EQ(nearestStampIndex({0.0, 1.0, 2.0}, -5.0), 0u);
  EXPECT_EQ(nearestStampIndex({0.0, 1.0, 2.0}, 7.0), 2u);
  EXPECT_EQ(nearestStampIndex({0.0, 1.0, 1.0, 2.0}, 1.2), 1u);
}

TEST(Association, MissingStampsAreSkippedOnEitherSide) {
  // Reference at 0.0 .. 0.9; the estimate lacks 0.3 and 0.7 and has an extra stamp at 5.0.
  const Trajectory ref = stampsOnly({0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9});
  const Trajectory est = stampsOnly({0.002, 0.1, 0.2, 0.4, 0.5, 0.6, 0.8, 0.9, 5.0});
  const AssociatedPoses pairs = associate(est, ref);
  ASSERT_EQ(pairs.size(), 8u);
  EXPECT_THAT(times(pairs.ref), ::testing::ElementsAre(0.0, 0.1, 0.2, 0.4, 0.5, 0.6, 0.8, 0.9));
  EXPECT_THAT(times(pairs.est), ::testing::ElementsAre(0.002, 0.1, 0.2, 0.4, 0.5, 0.6, 0.8, 0.9));
}

TEST(Association, ToleranceIsInclusiveAndDropsFartherStamps) {
  const Trajectory ref = stampsOnly({0.0, 1.0, 2.0, 3.0});
  const Trajectory est = stampsOnly({0.25, 1.02, 2.0, 3.5});
  EXPECT_EQ(associate(est, ref).size(), 1u);  // only 2.0 within 0.01 s
  const AssociatedPoses pairs = associate(est, ref, {.t_max_diff_s = 0.25});
  EXPECT_THAT(times(pairs.est), ::testing::ElementsAre(0.25, 1.02, 2.0));
  EXPECT_THAT(times(pairs.ref), ::testing::ElementsAre(0.0, 1.0, 2.0));
}

TEST(Association, OffsetIsAddedToTheEstimateTimes) {
  // The estimate's clock is 0.5 s behind: est time + 0.5 = reference time.
  const Trajectory ref = stampsOnly({10.0, 10.1, 10.2, 10.3});
  const Trajectory est_short = stampsOnly({9.5, 9.6, 9.7});
  const Trajectory est_long = stampsOnly({9.5, 9.55, 9.6, 9.65, 9.7, 9.75, 9.8});
  EXPECT_EQ(associate(est_short, ref).size(), 0u);
  const AssociatedPoses a = associate(est_short, ref, {.t_offset_s = 0.5});
  EXPECT_THAT(times(a.est), ::testing::ElementsAre(9.5, 9.6, 9.7));
  EXPECT_THAT(times(a.ref), ::testing::ElementsAre(10.0, 10.1, 10.2));
  // The estimate is the longer trajectory here, the other branch of evo's algorithm.
  const AssociatedPoses b = associate(est_long, ref, {.t_offset_s = 0.5});
  EXPECT_THAT(times(b.est), ::testing::ElementsAre(9.5, 9.6, 9.7, 9.8));
  EXPECT_THAT(times(b.ref), ::testing::ElementsAre(10.0, 10.1, 10.2, 10.3));
}

TEST(Association, ALargeToleranceCanReuseAPoseAsEvoDoes) {
  // Both estimate stamps are nearest to reference 1.0; evo keeps both pairs.
  const Trajectory ref = stampsOnly({0.0, 1.0, 2.0});
  const Trajectory est = stampsOnly({0.9, 1.1});
  const AssociatedPoses pairs = associate(est, ref, {.t_max_diff_s = 0.2});
  EXPECT_THAT(times(pairs.ref), ::testing::ElementsAre(1.0, 1.0));
  EXPECT_THAT(times(pairs.est), ::testing::ElementsAre(0.9, 0.9));  // reverse pass: nearest to 1.0
}

TEST(Umeyama, RecoversAKnownRotationTranslationAndScale) {
  const lie::SO3 R = lie::SO3::fromAxisAngle({1.0, -2.0, 0.5}, 0.7);
  const Eigen::Vector3d t(3.0, -4.0, 12.5);
  const double scale = 1.7;
  const std::vector<Eigen::Vector3d> source{{0, 0, 0}, {1, 0, 0}, {0, 2, 0},
                                            {0, 0, 3}, {1, 1, 1}, {-2, 0.5, 4}};
  std::vector<Eigen::Vector3d> target, target_rigid;
  for (const auto& p : source) {
    target.push_back(scale * (R * p) + t);
    target_rigid.push_back(R * p + t);
  }
  const AlignmentTransform sim3 = umeyama(source, target, true);
  EXPECT_NEAR(sim3.scale, scale, 1e-12);
  EXPECT_TRUE(sim3.T_ref_est.rotation().matrix().isApprox(R.matrix(), 1e-12));
  EXPECT_TRUE(sim3.T_ref_est.translation().isApprox(t, 1e-12));

  const AlignmentTransform se3 = umeyama(source, target_rigid, false);
  EXPECT_EQ(se3.scale, 1.0);
  EXPECT_TRUE(se3.T_ref_est.rotation().matrix().isApprox(R.matrix(), 1e-12));
  EXPECT_TRUE(se3.T_ref_est.translation().isApprox(t, 1e-12));
}

TEST(Umeyama, PlanarPointsStillGiveAProperRotation) {
  // Points in a plane: the covariance has rank 2 and the reflection check picks det(R) = +1.
  const lie::SO3 R = lie::SO3::fromAxisAngle({0.0, 0.0, 1.0}, 2.5);
  const std::vector<Eigen::Vector3d> source{{0, 0, 0}, {4, 0, 0}, {0, 3, 0}, {2, 5, 0}};
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.push_back(R * p);
  const AlignmentTransform a = umeyama(source, target, false);
  EXPECT_NEAR(a.T_ref_est.rotation().matrix().determinant(), 1.0, 1e-12);
  EXPECT_TRUE(a.T_ref_est.rotation().matrix().isApprox(R.matrix(), 1e-12));
}

TEST(Umeyama, PointsOnALineAreRefused) {
  const std::vector<Eigen::Vector3d> line{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  const std::string message =
      taiga::test::messageOf<InputError>([&] { umeyama(line, line, false); });
  EXPECT_THAT(message, HasSubstr("lie on a line"));
}

TEST(Alignment, OriginPutsTheFirstEstimatedPoseOnTheFirstReferencePose) {
  const std::vector<StampedPose> ref = test::curvedPath(20);
  const lie::SE3 T_est_ref(lie::SO3::fromAxisAngle({0.3, 1.0, -0.2}, 1.1), {5.0, -7.0, 2.0});
  const std::vector<StampedPose> est = test::transformed(T_est_ref, ref);
  const AlignmentTransform origin = computeAlignment(est, ref, Alignment::kOrigin);
  const std::vector<StampedPose> aligned = applyAlignment(est, origin);
  for (std::size_t i = 0; i < ref.size(); ++i) {
    EXPECT_TRUE(aligned[i].pose.translation().isApprox(ref[i].pose.translation(), 1e-12)) << i;
    EXPECT_TRUE(
        aligned[i].pose.rotation().matrix().isApprox(ref[i].pose.rotation().matrix(), 1e-12));
  }
}

TEST(Alignment, Sim3ScalesPositionsBeforeTheRigidTransform) {
  const std::vector<StampedPose> ref = test::curvedPath(30);
  std::vector<StampedPose> est;
  const lie::SE3 T(lie::SO3::fromAxisAngle({0.0, 0.0, 1.0}, -0.4), {1.0, 2.0, 3.0});
  for (const StampedPose& p : ref)  // est = T * (0.5 * ref positions), orientation T * R
    est.push_back({p.t_s, T * lie::SE3(p.pose.rotation(), 0.5 * p.pose.translation())});
  const AlignmentTransform sim3 = computeAlignment(est, ref, Alignment::kSim3);
  EXPECT_NEAR(sim3.scale, 2.0, 1e-12);
  const std::vector<StampedPose> aligned = applyAlignment(est, sim3);
  for (std::size_t i = 0; i < ref.size(); ++i)
    EXPECT_TRUE(aligned[i].pose.translation().isApprox(ref[i].pose.translation(), 1e-11)) << i;
  const AlignmentTransform none = computeAlignment(est, ref, Alignment::kNone);
  EXPECT_EQ(none.scale, 1.0);
  EXPECT_TRUE(none.T_ref_est.matrix().isIdentity(0.0));
}

TEST(Alignment, WithOrientationsAStraightPathsRollIsTheOrientationsAndACurvedOneUmeyamas) {
  // A straight path of 2 m whose positions wobble by a millimetre across it (the harvester's
  // strip road): Umeyama leaves the rotation about it to the wobble. The estimate is the truth
  // rolled by 5 deg about the path (x) and moved, with 3 mm of noise on its positions.
  std::vector<StampedPose> ref;
  for (int i = 0; i < 50; ++i)
    ref.push_back({0.1 * i, lie::SE3(lie::SO3::fromAxisAngle({0.0, 0.0, 1.0}, 0.02 * i),
                                     {0.04 * i, 0.001 * std::sin(i), 0.001 * std::cos(2.0 * i)})});
  const lie::SE3 T_est_ref(lie::SO3::fromAxisAngle({1.0, 0.0, 0.0}, 5.0 * std::numbers::pi / 180.0),
                           {3.0, -1.0, 0.5});
  std::vector<StampedPose> est = test::transformed(T_est_ref, ref);
  for (std::size_t i = 0; i < est.size(); ++i)
    est[i].pose = lie::SE3(
        est[i].pose.rotation(),
        est[i].pose.translation() +
            0.003 * Eigen::Vector3d(std::cos(3.0 * i), std::sin(5.0 * i), std::sin(7.0 * i)));
  const double umeyama_error_deg =
      (computeAlignment(est, ref, Alignment::kSe3).T_ref_est * T_est_ref).rotation().angle() *
      180.0 / std::numbers::pi;
  const double with_error_deg =
      (alignWithOrientations(est, ref, 0.1).T_ref_est * T_est_ref).rotation().angle() * 180.0 /
      std::numbers::pi;
  EXPECT_GT(umeyama_error_deg, 1.0) << "the degeneracy this test is about has gone away";
  EXPECT_LT(with_error_deg, 0.05);

  // On a curved path the positions decide, and both agree.
  const std::vector<StampedPose> curved = test::curvedPath(30);
  const std::vector<StampedPose> moved = test::transformed(T_est_ref, curved);
  const lie::SE3 a = computeAlignment(moved, curved, Alignment::kSe3).T_ref_est;
  const lie::SE3 b = alignWithOrientations(moved, curved, 0.1).T_ref_est;
  EXPECT_TRUE(a.matrix().isApprox(b.matrix(), 1e-9));
}

TEST(Alignment, NamesParseAndBadNamesAreRefused) {
  EXPECT_EQ(parseAlignment("sim3"), Alignment::kSim3);
  EXPECT_EQ(alignmentName(parseAlignment("origin")), "origin");
  EXPECT_THAT(taiga::test::messageOf<InputError>([] { parseAlignment("umeyama"); }),
              HasSubstr("'umeyama' is not one of se3, sim3, origin, none"));
}

}  // namespace
}  // namespace taiga::eval
