// APE, RPE, KITTI errors, drift, distance distribution and statistics on hand-computed cases.
#include <gmock/gmock.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

#include "../support/temp_dir.hpp"
#include "eval_test_support.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/eval/drift.hpp"
#include "taiga/eval/evaluate.hpp"
#include "taiga/eval/kitti_errors.hpp"
#include "taiga/eval/pose_errors.hpp"
#include "taiga/eval/statistics.hpp"

namespace taiga::eval {
namespace {

using ::testing::ElementsAre;
using ::testing::Pair;

TEST(Statistics, MatchNumpyDefinitions) {
  const std::vector<double> v{4.0, 1.0, 3.0, 2.0};
  const ErrorStatistics s = computeStatistics(v);
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));  // (16 + 1 + 9 + 4) / 4
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population: (2.25 + 0.25 + 0.25 + 2.25) / 4
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(percentile(v, 95.0), 3.85);  // rank 2.85 between 3 and 4
  EXPECT_EQ(percentile(v, 0.0), 1.0);
  EXPECT_EQ(percentile(v, 100.0), 4.0);
  EXPECT_EQ(computeStatistics(std::vector<double>{5.0, 1.0, 3.0}).median, 3.0);
  EXPECT_EQ(computeStatistics(std::vector<double>{}).count, 0u);
}

TEST(Ape, ConstantOffsetIsThatOffsetUnalignedAndZeroAfterSe3) {
  const std::vector<StampedPose> ref = test::curvedPath(100);
  const std::vector<StampedPose> est =
      test::transformed(lie::SE3(lie::SO3(), {1.0, 2.0, 2.0}), ref);  // |offset| = 3 m
  const ApeResult none = computeApe(est, ref, true);
  EXPECT_NEAR(none.translation_m.rmse, 3.0, 1e-12);
  EXPECT_NEAR(none.translation_m.mean, 3.0, 1e-12);
  EXPECT_NEAR(none.translation_m.std, 0.0, 1e-12);
  EXPECT_NEAR(none.translation_m.max, 3.0, 1e-12);
  EXPECT_TRUE(none.rmse_per_axis_m.isApprox(Eigen::Vector3d(1.0, 2.0, 2.0), 1e-12));
  EXPECT_NEAR(none.rotation_deg->max, 0.0, 1e-6);

  const Trajectory est_traj(est), ref_traj(ref);
  const EvalResult se3 = evaluate(est_traj, ref_traj, {.alignment = Alignment::kSe3});
  EXPECT_NEAR(se3.ape.translation_m.rmse, 0.0, 1e-9);
  EXPECT_EQ(se3.pairs.size(), 100u);
  const EvalResult unaligned = evaluate(est_traj, ref_traj, {.alignment = Alignment::kNone});
  EXPECT_NEAR(unaligned.ape.translation_m.rmse, 3.0, 1e-12);
}

TEST(Ape, RotationPartIsTheAngleOfTheRelativeRotationInDegrees) {
  const std::vector<StampedPose> ref = test::curvedPath(50);
  std::vector<StampedPose> est;
  for (std::size_t i = 0; i < ref.size(); ++i) {  // odd poses turned 10 deg, even ones 4 deg
    const double angle = (i % 2 == 1 ? 10.0 : 4.0) * kRadPerDeg;
    est.push_back({ref[i].t_s, ref[i].pose * lie::SE3(lie::SO3::fromAxisAngle({1, 1, 0}, angle),
                                                      Eigen::Vector3d::Zero())});
  }
  const ApeResult ape = computeApe(est, ref, true);
  ASSERT_TRUE(ape.rotation_deg);
  EXPECT_NEAR(ape.rotation_deg->mean, 7.0, 1e-9);
  EXPECT_NEAR(ape.rotation_deg->max, 10.0, 1e-9);
  EXPECT_NEAR(ape.rotation_deg->min, 4.0, 1e-9);
  EXPECT_NEAR(ape.rotation_deg->rmse, std::sqrt((100.0 + 16.0) / 2.0), 1e-9);
  EXPECT_NEAR(ape.translation_m.max, 0.0, 1e-12);
  EXPECT_FALSE(computeApe(est, ref, false).rotation_deg.has_value());
}

TEST(Rpe, ConstantPerStepErrorOverFrames) {
  // Reference steps 1 m along x, the estimate 1.1 m: every step is 0.1 m too long.
  const std::vector<StampedPose> ref = test::straightLine(11, 1.0);
  const std::vector<StampedPose> est = test::straightLine(11, 1.1);
  const RpeResult one = computeRpe(est, ref, {1.0, DeltaUnit::kFrames});
  EXPECT_EQ(one.pairs.size(), 10u);
  EXPECT_NEAR(one.translation_m.mean, 0.1, 1e-12);
  EXPECT_NEAR(one.translation_m.std, 0.0, 1e-12);
  EXPECT_NEAR(one.rotation_deg.max, 0.0, 1e-12);
  // delta 3 frames: consecutive pairs (0,3), (3,6), (6,9), each 0.3 m too long.
  const RpeResult three = computeRpe(est, ref, {3.0, DeltaUnit::kFrames});
  EXPECT_THAT(three.pairs, ElementsAre(Pair(0u, 3u), Pair(3u, 6u), Pair(6u, 9u)));
  EXPECT_NEAR(three.translation_m.rmse, 0.3, 1e-12);
}

TEST(Rpe, DeltaInMetresFollowsEvosPathFilterOnTheEstimate) {
  const std::vector<StampedPose> ref = test::straightLine(11, 1.0);
  const std::vector<StampedPose> est = test::straightLine(11, 1.1);
  // Path along the estimate 1.1, 2.2 (>= 2: keep 2, restart), 1.1, 2.2 (keep 4), ...
  const RpeResult r = computeRpe(est, ref, {2.0, DeltaUnit::kMetres});
  EXPECT_THAT(r.pairs, ElementsAre(Pair(2u, 4u), Pair(4u, 6u), Pair(6u, 8u), Pair(8u, 10u)));
  EXPECT_NEAR(r.translation_m.mean, 0.2, 1e-12);
}

TEST(Rpe, ConstantYawErrorPerStep) {
  std::vector<StampedPose> ref = test::straightLine(6, 1.0), est;
  for (std::size_t i = 0; i < ref.size(); ++i)  // the estimate turns 2 deg more per step
    est.push_back({ref[i].t_s, test::yawPose(2.0 * kRadPerDeg * static_cast<double>(i),
                                             ref[i].pose.translation())});
  const RpeResult r = computeRpe(est, ref, {1.0, DeltaUnit::kFrames});
  EXPECT_NEAR(r.rotation_deg.min, 2.0, 1e-9);
  EXPECT_NEAR(r.rotation_deg.max, 2.0, 1e-9);
}

TEST(Rpe, RefusesDeltasThatAreNotPositiveWholeFrames) {
  const std::vector<StampedPose> line = test::straightLine(5, 1.0);
  EXPECT_THROW(computeRpe(line, line, {0.0, DeltaUnit::kFrames}), InputError);
  EXPECT_THROW(computeRpe(line, line, {1.5, DeltaUnit::kFrames}), InputError);
  EXPECT_THROW(computeRpe(line, line, {-2.0, DeltaUnit::kMetres}), InputError);
  EXPECT_TRUE(computeRpe(line, line, {10.0, DeltaUnit::kFrames}).pairs.empty());
}

// Mean of the devkit's segment errors on a 1000 m straight line with 1 m steps: a segment from
// frame f of length L ends at frame f + L + 1 (the first with distance > L), so it spans L + 1 m,
// and the segments of length L start at f = 0, 10, ... <= 999 - L.
double meanOverKittiSegments(double error_per_metre_of_span) {
  double sum = 0.0, count = 0.0;
  for (int length = 100; length <= 800; length += 100) {
    const int segments = (999 - length) / 10 + 1;
    sum += segments * error_per_metre_of_span * (length + 1.0) / length;
    count += segments;
  }
  return sum / count;
}

TEST(Kitti, OnePercentTooLongGivesOnePercentTranslationalError) {
  const std::vector<StampedPose> ref = test::straightLine(1001, 1.0);
  const std::vector<StampedPose> est = test::straightLine(1001, 1.01);
  const std::optional<KittiResult> k = computeKittiErrors(est, ref);
  ASSERT_TRUE(k);
  EXPECT_EQ(k->segments.size(), 90u + 80u + 70u + 60u + 50u + 40u + 30u + 20u);
  EXPECT_NEAR(k->translation_error_percent, 100.0 * meanOverKittiSegments(0.01), 1e-9);
  EXPECT_NEAR(k->translation_error_percent, 1.0, 0.006);  // the span is L + 1 m, not L
  EXPECT_NEAR(k->rotation_error_deg_per_100m, 0.0, 1e-9);
}

TEST(Kitti, ConstantYawRateGivesItsRotationalError) {
  // The estimate's heading drifts 0.001 rad per metre travelled: 5.73 deg per 100 m.
  const std::vector<StampedPose> ref = test::straightLine(1001, 1.0);
  std::vector<StampedPose> est;
  for (std::size_t i = 0; i < ref.size(); ++i)
    est.push_back(
        {ref[i].t_s, test::yawPose(0.001 * static_cast<double>(i), ref[i].pose.translation())});
  const std::optional<KittiResult> k = computeKittiErrors(est, ref);
  ASSERT_TRUE(k);
  EXPECT_NEAR(k->rotation_error_deg_per_100m, meanOverKittiSegments(0.001) * kDegPerRad * 100.0,
              1e-9);
}

TEST(Kitti, NoSegmentsOnAPathShorterThan100Metres) {
  const std::vector<StampedPose> line = test::straightLine(100, 1.0);  // 99 m
  EXPECT_FALSE(computeKittiErrors(line, line).has_value());
}

TEST(Drift, EndPointErrorAfterAligningTheFirstPose) {
  // 100 m along x; the estimate ends 3 m off in y and 4 m in z, and lives in another frame.
  const std::vector<StampedPose> ref = test::straightLine(101, 1.0);
  std::vector<StampedPose> est_local = ref;
  est_local.back().pose = lie::SE3(lie::SO3(), {100.0, 3.0, 4.0});
  const lie::SE3 T(lie::SO3::fromAxisAngle({0.2, 0.1, 1.0}, 0.5), {10.0, -5.0, 2.0});
  const DriftResult d = computeDrift(test::transformed(T, est_local), ref);
  EXPECT_NEAR(d.drift_m, 5.0, 1e-9);
  EXPECT_TRUE(d.drift_vector_m.isApprox(Eigen::Vector3d(0.0, 3.0, 4.0), 1e-9));
  EXPECT_NEAR(d.reference_path_length_m, 100.0, 1e-12);
  EXPECT_NEAR(d.drift_percent, 5.0, 1e-9);
}

TEST(Drift, PathLengthRatioIsTheStepsScaleWhateverTheFrameAndThePoseNoise) {
  const std::vector<StampedPose> ref = test::curvedPath(200);  // 0.5 m steps
  std::vector<StampedPose> est = ref;
  for (StampedPose& p : est) p.pose = lie::SE3(p.pose.rotation(), 0.999 * p.pose.translation());
  est = test::transformed(lie::SE3(lie::SO3::Exp({0.1, 0.2, 0.3}), {5.0, -2.0, 1.0}), est);
  EXPECT_NEAR(computeDrift(est, ref).path_length_ratio, 0.999, 1e-9);

  // Poses 5 mm to either side in turn: a sum over every 0.5 m step would be 2e-4 too long, over
  // steps of 1.5 m (every third pose: 1 m or more) 2.2e-5.
  std::vector<StampedPose> noisy = ref;
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    const Eigen::Vector3d side = noisy[i].pose.rotation() * Eigen::Vector3d::UnitY();
    noisy[i].pose = lie::SE3(noisy[i].pose.rotation(),
                             noisy[i].pose.translation() + (i % 2 ? 0.005 : -0.005) * side);
  }
  EXPECT_NEAR(computeDrift(noisy, ref).path_length_ratio, 1.0, 3e-5);

  const std::vector<StampedPose> standing = test::straightLine(10, 0.05);  // 0.45 m in all
  EXPECT_EQ(computeDrift(standing, standing).path_length_ratio, 0.0);
}

TEST(Drift, HeadingAlignedDriftIgnoresTheFirstPosesTiltButNotAWorldTilt) {
  // 100 m along x, exact, in a frame turned by 30 deg about z and shifted; only the first pose's
  // attitude is 1 deg off in pitch. Aligned on that pose, the end point is 1.75 m off in z; with
  // position and heading only it is exact.
  const std::vector<StampedPose> ref = test::straightLine(101, 1.0);
  const lie::SE3 T(lie::SO3::fromRollPitchYaw(0.0, 0.0, 0.5), {10.0, -5.0, 2.0});
  std::vector<StampedPose> est = test::transformed(T, ref);
  est.front().pose = lie::SE3(est.front().pose.rotation() *
                                  lie::SO3::fromRollPitchYaw(0.0, 1.0 * kRadPerDeg, 0.0),
                              est.front().pose.translation());
  const DriftResult d = computeDrift(est, ref);
  EXPECT_NEAR(std::abs(d.drift_vector_m.z()), 100.0 * std::sin(1.0 * kRadPerDeg), 1e-6);
  EXPECT_LT(d.heading_aligned_drift_vector_m.norm(), 1e-9);
  // A world tilted by 1 deg about y (the whole estimate, first pose included) stays visible.
  const std::vector<StampedPose> tilted =
      test::transformed(lie::SE3(lie::SO3::fromRollPitchYaw(0.0, 1.0 * kRadPerDeg, 0.0), {}), ref);
  EXPECT_NEAR(std::abs(computeDrift(tilted, ref).heading_aligned_drift_vector_m.z()),
              100.0 * std::sin(1.0 * kRadPerDeg), 1e-6);
}

TEST(Distance, HistogramInTenthsOfAMetreAndItsSpread) {
  const std::vector<double> distances{0.05, 0.15, 0.16, 0.25, 0.27, 0.28};
  std::vector<StampedPose> a, b;
  for (std::size_t i = 0; i < distances.size(); ++i) {
    const double t = static_cast<double>(i);
    a.push_back({t, lie::SE3(lie::SO3(), {t, 0.0, 0.0})});
    b.push_back({t, lie::SE3(lie::SO3(), {t, 0.6 * distances[i], 0.8 * distances[i]})});
  }
  const DistanceDistribution d = computeDistanceDistribution(a, b, 0.1);
  EXPECT_THAT(d.counts, ElementsAre(1u, 2u, 3u));
  EXPECT_NEAR(d.first_bin_start_m, 0.0, 1e-15);
  EXPECT_NEAR(d.mean_m, 1.16 / 6.0, 1e-12);
  double mean_square = 0.0;
  for (const double x : distances) mean_square += x * x / 6.0;
  EXPECT_NEAR(d.std_m, std::sqrt(mean_square - (1.16 / 6.0) * (1.16 / 6.0)), 1e-12);
  EXPECT_NEAR(d.min_m, 0.05, 1e-12);
  EXPECT_NEAR(d.max_m, 0.28, 1e-12);
  // Distances between 1.05 and 1.28 m start at the bin [1.0, 1.1).
  for (std::size_t i = 0; i < distances.size(); ++i)
    b[i].pose = lie::SE3(lie::SO3(), a[i].pose.translation() +
                                         (1.0 + distances[i]) * Eigen::Vector3d(0.0, 0.6, 0.8));
  const DistanceDistribution far = computeDistanceDistribution(a, b, 0.1);
  EXPECT_NEAR(far.first_bin_start_m, 1.0, 1e-12);
  EXPECT_THROW(computeDistanceDistribution(a, b, 0.0), InputError);
  EXPECT_THAT(taiga::test::messageOf<InputError>([&] { computeDistanceDistribution(a, b, 1e-7); }),
              ::testing::HasSubstr("choose a wider bin"));
}

TEST(Evaluate, NoMatchingStampsIsAnInputErrorNamingTheTolerance) {
  const Trajectory ref(test::curvedPath(10, 100.0));
  const Trajectory est(test::curvedPath(10, 200.0));
  EXPECT_THAT(taiga::test::messageOf<InputError>([&] { evaluate(est, ref, {}); }),
              ::testing::HasSubstr("no matching time stamps"));
  // The spans do not overlap: the offset that matches the starts.
  EXPECT_THAT(taiga::test::messageOf<InputError>([&] { evaluate(est, ref, {}); }),
              ::testing::HasSubstr("--t-offset -100.000000 would make them match"));
  // Stamped 30 ms late: 30 ms back; half a period late (scan end against scan start): both
  // neighbours match, the one before is taken.
  for (const double late_s : {0.03, 0.05}) {
    std::vector<StampedPose> shifted = test::curvedPath(10, 100.0);
    for (StampedPose& p : shifted) p.t_s += late_s;
    EXPECT_THAT(
        taiga::test::messageOf<InputError>([&] { evaluate(Trajectory(shifted), ref, {}); }),
        ::testing::HasSubstr(fmt::format("--t-offset {:.6f} would make them match", -late_s)));
  }
}

}  // namespace
}  // namespace taiga::eval
